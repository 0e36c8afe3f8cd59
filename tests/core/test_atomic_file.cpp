// write_file_atomically: the whole file or nothing, typed errors naming the path, and a killed
// writer's temporary file cleaned up by the next write.
#include <catch2/catch.hpp>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "handcentric/core/atomic_file.hpp"
#include "handcentric/core/errors.hpp"

using namespace handcentric;

namespace {

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

TEST_CASE("files_are_written_atomically_and_bad_paths_are_typed_errors", "[unit]") {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / "handcentric_test_atomic_file";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "CLAIMS.md").string();
  write_file_atomically(path, "old\n");
  write_file_atomically(path, "new\n");
  CHECK(read_file(path) == "new\n");
  CHECK(std::distance(std::filesystem::directory_iterator(dir),
                      std::filesystem::directory_iterator()) == 1);
  CHECK_THROWS_AS(write_file_atomically((dir / "missing" / "x.md").string(), "x"), FileError);
  CHECK_THROWS_WITH(write_file_atomically((dir / "missing" / "x.md").string(), "x"),
                    Catch::Contains("missing/x.md") && Catch::Contains("directory"));
  CHECK_THROWS_AS(write_file_atomically(dir.string(), "x"), FileError);  // a directory
  CHECK_THROWS_AS(write_file_atomically("", "x"), FileError);
  std::filesystem::remove_all(dir);
}

TEST_CASE("a_killed_writers_temporary_file_is_removed_by_the_next_write_and_a_live_ones_is_kept",
          "[unit]") {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / "handcentric_test_atomic_stale";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  // A process that has exited and been reaped: its pid names a writer that is gone.
  const pid_t gone = ::fork();
  if (gone == 0) ::_exit(0);
  REQUIRE(gone > 0);
  ::waitpid(gone, nullptr, 0);
  const std::filesystem::path stale = dir / ("model.hcm.tmp." + std::to_string(gone));
  const std::filesystem::path live = dir / ("model.hcm.tmp." + std::to_string(::getppid()));
  const std::filesystem::path other = dir / ("other.hcm.tmp." + std::to_string(gone));
  for (const auto& leftover : {stale, live, other}) std::ofstream(leftover) << "partial";

  write_file_atomically((dir / "model.hcm").string(), "whole\n");
  CHECK(read_file(dir / "model.hcm") == "whole\n");
  CHECK_FALSE(std::filesystem::exists(stale));
  CHECK(std::filesystem::exists(live));   // its writer may still be writing
  CHECK(std::filesystem::exists(other));  // another path's temporary file is not ours to judge
  std::filesystem::remove_all(dir);
}
