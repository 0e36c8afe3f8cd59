#include "handcentric/core/format.hpp"
#include "handcentric/experiments/progress.hpp"

#include <unistd.h>

namespace handcentric::experiments {

Progress::Progress(int jobs, double total_work, std::FILE* out, bool quiet)
    : out_(out),
      quiet_(quiet),
      terminal_(::isatty(::fileno(out)) != 0),
      jobs_(jobs),
      total_work_(total_work) {}

std::string Progress::clock(double seconds) {
  return format_clock(seconds);
}

void Progress::start(int worker, const std::string& what) {
  const std::lock_guard lock(mutex_);
  running_[worker] = what;
  print_locked("start " + what);
}

void Progress::finish(int worker, double work, bool skipped) {
  const std::lock_guard lock(mutex_);
  const std::string what = running_[worker];
  running_.erase(worker);
  ++done_;
  if (skipped) {
    total_work_ -= work;
  } else {
    done_work_ += work;
  }
  print_locked((skipped ? "found " : "done ") + what);
}

void Progress::print_locked(const std::string& event) {
  if (quiet_) return;
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::string eta = "?";
  if (done_work_ > 0.0) eta = clock(elapsed / done_work_ * std::max(0.0, total_work_ - done_work_));
  std::string running;
  for (const auto& [worker, what] : running_) running += (running.empty() ? "" : "; ") + what;
  if (terminal_) {
    std::fprintf(out_, "\r\033[K[%d/%d] %s elapsed, ETA %s | %s", done_, jobs_,
                 clock(elapsed).c_str(), eta.c_str(),
                 running.empty() ? event.c_str() : running.c_str());
    if (done_ == jobs_) std::fprintf(out_, "\n");
  } else {
    std::fprintf(out_, "[%d/%d] %s elapsed, ETA %s: %s\n", done_, jobs_, clock(elapsed).c_str(),
                 eta.c_str(), event.c_str());
  }
  std::fflush(out_);
}

}  // namespace handcentric::experiments
