// write_file_atomically: the whole file or nothing, and typed errors naming the path.
#include <catch2/catch.hpp>
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
  CHECK(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()) ==
        1);
  CHECK_THROWS_AS(write_file_atomically((dir / "missing" / "x.md").string(), "x"), FileError);
  CHECK_THROWS_WITH(write_file_atomically((dir / "missing" / "x.md").string(), "x"),
                    Catch::Contains("missing/x.md") && Catch::Contains("directory"));
  CHECK_THROWS_AS(write_file_atomically(dir.string(), "x"), FileError);  // a directory
  CHECK_THROWS_AS(write_file_atomically("", "x"), FileError);
  std::filesystem::remove_all(dir);
}
