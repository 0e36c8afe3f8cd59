#pragma once
// A progress display for a grid of jobs on stderr: what runs, done / total, elapsed and ETA.
// On a terminal one line is rewritten in place; otherwise a line is printed when a job starts or
// ends. Thread-safe (workers report from their own threads).
#include <chrono>
#include <cstdio>
#include <map>
#include <mutex>
#include <string>

namespace handcentric::experiments {

class Progress {
 public:
  /// `total_work`: the sum of the work units of every job still to do (e.g. training steps);
  /// the ETA assumes the remaining work goes at the rate of the work done so far.
  Progress(int jobs, double total_work, std::FILE* out = stderr, bool quiet = false);

  void start(int worker, const std::string& what);
  /// A job of `work` units finished (`skipped`: found done, not counted in the rate).
  void finish(int worker, double work, bool skipped = false);

  /// "3:05" style (h:mm:ss above an hour).
  static std::string clock(double seconds);

 private:
  void print_locked(const std::string& event);

  std::mutex mutex_;
  std::FILE* out_;
  bool quiet_, terminal_;
  int jobs_, done_ = 0;
  double total_work_, done_work_ = 0.0;
  std::map<int, std::string> running_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace handcentric::experiments
