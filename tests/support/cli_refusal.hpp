#pragma once
// The bounded-input tests' check on the command line: a damaged file given to `handcentric` is
// refused with exit status 1 and one line on stderr that names the file and what is wrong, and
// refusing it stays within the memory limit of child_process.hpp.
#include <catch2/catch.hpp>

#include <algorithm>
#include <string>
#include <vector>

#include "child_process.hpp"

namespace handcentric::test {

/// Runs `argv` (the command line that reads the damaged file `path`) and checks the refusal:
/// exit 1, one stderr line "handcentric: error: ..." containing `path` and `what`, peak memory
/// under kPeakMemoryLimitBytes.
inline void check_cli_refuses(const std::vector<std::string>& argv, const std::string& path,
                              const std::string& what) {
  using Catch::Matchers::Contains;
  const ChildRun run = run_program(argv);
  INFO("stderr: " << run.err << "peak " << run.peak_bytes / (1 << 20) << " MB");
  CHECK(run.exit_code == 1);
  CHECK(std::count(run.err.begin(), run.err.end(), '\n') == 1);
  CHECK_THAT(run.err, Contains("handcentric: error: ") && Contains(path) && Contains(what));
  CHECK(run.peak_bytes < kPeakMemoryLimitBytes);
}

}  // namespace handcentric::test
