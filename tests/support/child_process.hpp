#pragma once
// Runs a function or a program in a child process and measures its peak memory: the
// bounded-input tests (docs/RELIABILITY.md, item 4) assert that refusing a hostile file costs less
// than kPeakMemoryLimitBytes, and a child keeps a regression (an attempt to allocate terabytes)
// from taking the test process, or the machine, down with it.
//
// The peak is getrusage's ru_maxrss of the child (wait4), which on Linux includes the resident
// memory the child inherited at fork, so it over-estimates what the call itself used; each test
// case runs in its own process (ctest), whose memory at fork is small.
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace handcentric::test {

/// A path in the temporary folder unique to this process: the limit tests write their damaged
/// files there.
inline std::string limits_temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("handcentric_test_limits_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

constexpr long kPeakMemoryLimitBytes = 512L << 20;

struct ChildRun {
  int exit_code = -1;   ///< exit status; -1 when a signal ended the child
  int signal = 0;       ///< the signal that ended it, 0 if none
  std::string out;      ///< stdout (run_program) or what the function returned (run_in_child)
  std::string err;      ///< stderr (run_program)
  long peak_bytes = 0;  ///< ru_maxrss of the child
};

namespace detail {

inline std::string temp_file() {
  char path[] = "/tmp/handcentric_child_XXXXXX";
  const int fd = ::mkstemp(path);
  if (fd >= 0) ::close(fd);
  return path;
}

inline std::string slurp_and_remove(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  std::remove(path.c_str());
  return text.str();
}

// Without ASan, cap the child's address space so that a regression fails with bad_alloc instead
// of filling the machine's memory. ASan reserves terabytes of shadow memory, so it gets no cap;
// its allocator refuses sizes above max_allocation_size instead (a report, which fails the test).
inline void cap_memory() {
#if !defined(__SANITIZE_ADDRESS__) && !defined(HANDCENTRIC_ASAN)
  const rlimit limit{rlim_t{4} << 30, rlim_t{4} << 30};
  ::setrlimit(RLIMIT_AS, &limit);
#endif
}

inline ChildRun wait_for(pid_t pid) {
  ChildRun run;
  int status = 0;
  rusage usage{};
  if (::wait4(pid, &status, 0, &usage) < 0) return run;
  if (WIFEXITED(status)) run.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) run.signal = WTERMSIG(status);
  run.peak_bytes = usage.ru_maxrss * 1024L;  // Linux reports KiB
  return run;
}

}  // namespace detail

/// Runs `argv` (argv[0] is the program's path) with stdout and stderr captured.
inline ChildRun run_program(const std::vector<std::string>& argv) {
  const std::string out_path = detail::temp_file(), err_path = detail::temp_file();
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    detail::cap_memory();
    const int out = ::open(out_path.c_str(), O_WRONLY | O_TRUNC);
    const int err = ::open(err_path.c_str(), O_WRONLY | O_TRUNC);
    ::dup2(out, 1);
    ::dup2(err, 2);
    std::vector<char*> args;
    for (const std::string& arg : argv) args.push_back(const_cast<char*>(arg.c_str()));
    args.push_back(nullptr);
    ::execv(args[0], args.data());
    ::_exit(127);
  }
  ChildRun run = detail::wait_for(pid);
  run.out = detail::slurp_and_remove(out_path);
  run.err = detail::slurp_and_remove(err_path);
  return run;
}

/// Runs `fn` (returning a std::string) in a forked child; `out` is what it returned, exit code 0,
/// or "uncaught: <what>" with exit code 3 when it threw.
template <typename Fn>
ChildRun run_in_child(Fn fn) {
  const std::string out_path = detail::temp_file();
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    detail::cap_memory();
    int code = 0;
    std::string text;
    try {
      text = fn();
    } catch (const std::exception& error) {
      text = std::string("uncaught: ") + error.what();
      code = 3;
    }
    std::ofstream(out_path, std::ios::binary) << text;
    ::_exit(code);  // no atexit handlers, no Catch2 report from the child
  }
  ChildRun run = detail::wait_for(pid);
  run.out = detail::slurp_and_remove(out_path);
  return run;
}

}  // namespace handcentric::test
