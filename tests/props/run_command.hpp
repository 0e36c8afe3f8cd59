#pragma once
// Runs a shell command for the end-to-end tests: its exit status, stdout and stderr.
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace handcentric::test {

struct CommandResult {
  int exit_code = -1;
  std::string out, err;
};

inline CommandResult run_command(const std::string& command) {
  char err_path[] = "/tmp/handcentric_test_stderr_XXXXXX";
  const int fd = mkstemp(err_path);
  if (fd >= 0) close(fd);
  CommandResult result;
  FILE* pipe = popen((command + " 2>" + err_path).c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> chunk{};
  std::size_t n = 0;
  while ((n = std::fread(chunk.data(), 1, chunk.size(), pipe)) > 0)
    result.out.append(chunk.data(), n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream err_file(err_path);
  std::stringstream err;
  err << err_file.rdbuf();
  result.err = err.str();
  std::remove(err_path);
  return result;
}

/// The `handcentric` binary, the Python with NumPy, and the plug-ins, from CMake.
inline std::string cli() {
  return HANDCENTRIC_CLI;
}
inline std::string python() {
  return HANDCENTRIC_PYTHON;
}
inline std::string python_example() {
  // Appended piece by piece: GCC 12 at -O3 reports a false out-of-bounds memcpy for the chain
  // of operator+ on string literals once the calls are inlined into a unity build.
  std::string command = python();
  command += " ";
  command += HANDCENTRIC_SOURCE_DIR;
  command += "/examples/python_representation/repr.py";
  return command;
}
/// `python tests/props/plugins/<file> [arguments]`.
inline std::string test_plugin(const std::string& file, const std::string& arguments = "") {
  // Appended step by step: GCC 12 warns (-Warray-bounds, a false positive) on the one-expression
  // form with a conditional " " + arguments in some unity batches of this suite.
  std::string command = python();
  command += ' ';
  command += HANDCENTRIC_SOURCE_DIR;
  command += "/tests/props/plugins/";
  command += file;
  if (!arguments.empty()) {
    command += ' ';
    command += arguments;
  }
  return command;
}
inline std::string faulty_plugin(const std::string& mode) {
  return test_plugin("faulty.py", mode);
}

}  // namespace handcentric::test
