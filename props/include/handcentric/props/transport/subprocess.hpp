#pragma once
// A child process spoken to through pipes: started with /bin/sh -c in its own process group,
// its stdin written and its stdout read with deadlines (poll(), so nothing ever hangs), its
// stderr drained all along into a bounded tail (the last 20 lines), and, on destruction, its
// stdin closed, a short grace period to exit, then the whole group killed and the child reaped
// exactly once. The plug-in pipe (pipe_representation.hpp) is built on it.
//
// Constructing one ignores SIGPIPE for the process: a child that dies gives EPIPE, which is
// reported, instead of killing the caller. Not thread-safe.
#include <chrono>
#include <deque>
#include <optional>
#include <string>

#include "handcentric/core/errors.hpp"

namespace handcentric::props {

/// A plug-in that failed: not found, crashed, wrong answer, too slow.
class PluginError : public Error {
 public:
  using Error::Error;
};

class Subprocess {
 public:
  /// How a child ended.
  struct Exit {
    bool reaped = false;  ///< false: still running after the grace period, then killed
    bool exited = false;  ///< exited normally, with `status`
    int status = 0;
    bool signaled = false;  ///< killed by `signal`
    int signal = 0;
    std::string describe() const;  ///< "exited with status 3", "was killed by signal 9", ...
  };
  enum class Outcome { done, timed_out, closed, too_long };

  static constexpr int kStderrLines = 20;                ///< stderr lines kept
  static constexpr std::size_t kStderrLineBytes = 1000;  ///< longer lines are cut there
  /// The longest stdout line read_line accepts by default: 64 MiB, far above any answer (a
  /// chunk of 10^4 poses is ~3 MB), far below what would strain memory.
  static constexpr std::size_t kMaxLineBytes = std::size_t{64} << 20;

  /// Starts `command` through /bin/sh -c. Throws PluginError if the pipes or the process
  /// cannot be made.
  explicit Subprocess(std::string command, std::size_t max_line_bytes = kMaxLineBytes);
  ~Subprocess();
  Subprocess(const Subprocess&) = delete;
  Subprocess& operator=(const Subprocess&) = delete;

  /// Writes all of `bytes` to the child's stdin within `timeout` seconds.
  Outcome write_all(const std::string& bytes, double timeout);
  /// Reads one line (without its newline, "\r" dropped) from the child's stdout within
  /// `timeout` seconds; `line` is set only for Outcome::done. A line longer than
  /// max_line_bytes gives Outcome::too_long before more of it is buffered.
  Outcome read_line(std::string& line, double timeout);
  /// The last kStderrLines lines the child wrote on stderr (drained first).
  std::string stderr_tail();
  /// Kills the process group now (the shell and whatever it started).
  void kill();
  /// Closes stdin, waits up to `grace` seconds for the child to exit, kills the group if it has
  /// not, and reaps it. Safe to call more than once: later calls return the first result.
  Exit finish(double grace);

  const std::string& command() const { return command_; }
  bool running() const { return !exit_.has_value(); }

 private:
  void drain_stderr(bool until_eof);
  void close_fd(int& fd);

  std::string command_;
  std::size_t max_line_bytes_;
  int pid_ = -1;
  int stdin_ = -1, stdout_ = -1, stderr_ = -1;
  std::string stdout_buffer_;   ///< bytes read past the last newline
  std::string stderr_partial_;  ///< the stderr line being written
  std::deque<std::string> stderr_lines_;
  std::optional<Exit> exit_;
};

}  // namespace handcentric::props
