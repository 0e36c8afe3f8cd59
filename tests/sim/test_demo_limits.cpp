// Bounded input (docs/RELIABILITY.md, item 4): demo files over a DemoFileLimits bound are
// InvalidDemoFile errors naming the limit, raised before the loader reads or allocates what is over
// it. Each case runs load_demos in a child process, and `handcentric render --demos` as another,
// and checks that the child's peak memory stays under 512 MB (child_process.hpp).
#include <catch2/catch.hpp>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "child_process.hpp"  // tests/support
#include "cli_refusal.hpp"    // tests/support
#include "handcentric/sim/demos.hpp"

using namespace handcentric;
using namespace handcentric::sim;
using Catch::Matchers::Contains;

namespace {

const std::string kHeaderOfOne =
    R"({"clearance":0.1,"count":1,"format":"handcentric-demos","version":1})";
const std::string kPose = "[[1,0,0,0],[0,1,0,5],[0,0,1,0]]";
const std::string kRecordStart =
    R"({"world_T_hole":[[1,0,0,0],[0,1,0,0],[0,0,1,0]],"world_T_hand":[)";

// A record of `poses` poses (one line, with its newline).
std::string record_of(std::size_t poses) {
  std::string line = kRecordStart;
  line.reserve(kRecordStart.size() + poses * (kPose.size() + 1) + 3);
  for (std::size_t t = 0; t < poses; ++t) line += (t == 0 ? "" : ",") + kPose;
  return line + "]}\n";
}

void write_bytes(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// What load_demos(path, limits) throws, run in a child: "<type>: <message>".
test::ChildRun load_in_child(const std::string& path,
                             const DemoFileLimits& limits = DemoFileLimits()) {
  return test::run_in_child([&] {
    try {
      return "loaded " + std::to_string(load_demos(path, limits).size());
    } catch (const InvalidDemoFile& error) {
      return std::string("InvalidDemoFile: ") + error.what();
    }
  });
}

void check_refused(const test::ChildRun& run, const std::string& where, const std::string& what) {
  INFO(run.out << "\npeak " << run.peak_bytes / (1 << 20) << " MB");
  CHECK(run.exit_code == 0);
  CHECK_THAT(run.out, Contains("InvalidDemoFile") && Contains(where) && Contains(what));
  CHECK(run.peak_bytes < test::kPeakMemoryLimitBytes);
}

// `handcentric render --demos path` exits 1 with one line on stderr naming `what`, within the
// memory limit.
void check_cli_refuses(const std::string& path, const std::string& what) {
  test::check_cli_refuses(
      {HANDCENTRIC_CLI, "render", "--demos", path, "--out", test::limits_temp_path("never.png")},
      path, what);
}

}  // namespace

TEST_CASE("a_demo_line_of_a_billion_poses_is_refused_at_the_line_limit", "[unit]") {
  // A record that starts like a real one and goes on for 34 GB (10^9 poses' worth; sparse on
  // disk, the tail reads as zeros): refused once the line passes 4 MiB.
  const std::string path = test::limits_temp_path("long_line.jsonl");
  std::string start = kHeaderOfOne + "\n" + kRecordStart;
  while (start.size() < (std::size_t{5} << 20)) start += kPose + ",";
  write_bytes(path, start);
  std::filesystem::resize_file(path, std::uintmax_t{1'000'000'000} * (kPose.size() + 1));
  const std::string limit = std::to_string(DemoFileLimits().max_line_bytes);
  check_refused(load_in_child(path), "record 1 (line 2)", "longer than " + limit + " bytes");
  check_cli_refuses(path, "longer than " + limit + " bytes");
  std::filesystem::remove(path);
}

TEST_CASE("a_header_line_without_end_is_refused_at_the_line_limit", "[unit]") {
  // 2 GiB of zeros and no newline: the header is never read whole.
  const std::string path = test::limits_temp_path("no_newline.jsonl");
  write_bytes(path, "");
  std::filesystem::resize_file(path, std::uintmax_t{2} << 30);
  check_refused(load_in_child(path), "line 1 (header)", "longer than");
  check_cli_refuses(path, "longer than");
  std::filesystem::remove(path);
}

TEST_CASE("json_nested_deeper_than_the_limit_is_refused", "[unit]") {
  // 1,000,000 nested arrays in 2 MB: within the line limit, refused at depth 8.
  const std::string path = test::limits_temp_path("deep.jsonl");
  const std::size_t depth = 1'000'000;
  write_bytes(path, kHeaderOfOne + "\n" + std::string(depth, '[') + std::string(depth, ']') + "\n");
  check_refused(load_in_child(path), "record 1 (line 2)", "nested deeper than 8 levels");
  check_cli_refuses(path, "nested deeper than 8 levels");
  // the header too
  write_bytes(path, R"({"format":"handcentric-demos","version":1,"count":1,"x":)" +
                        std::string(depth, '[') + std::string(depth, ']') + "}\n");
  check_refused(load_in_child(path), "line 1 (header)", "nested deeper than 8 levels");
  std::filesystem::remove(path);
}

TEST_CASE("a_header_announcing_a_billion_demos_is_refused_before_any_record", "[unit]") {
  const std::string path = test::limits_temp_path("billion.jsonl");
  write_bytes(path,
              R"({"clearance":0.1,"count":1000000000,"format":"handcentric-demos","version":1})"
              "\n" +
                  record_of(1));
  check_refused(load_in_child(path), "line 1 (header)",
                "1000000000 demos, more than the limit of 100000");
  check_cli_refuses(path, "1000000000 demos");
  std::filesystem::remove(path);
}

TEST_CASE("a_demo_of_more_poses_than_the_limit_is_refused", "[unit]") {
  // 10001 poses: a 330 KB line, within the line limit.
  const std::string path = test::limits_temp_path("many_poses.jsonl");
  write_bytes(path, kHeaderOfOne + "\n" + record_of(10'001));
  check_refused(load_in_child(path), "record 1 (line 2)",
                "a demo of 10001 poses, more than the limit of 10000");
  check_cli_refuses(path, "10001 poses");
  // exactly at the limit it loads
  write_bytes(path, kHeaderOfOne + "\n" + record_of(10'000));
  const test::ChildRun at_limit = load_in_child(path);
  CHECK(at_limit.out == "loaded 1");
  std::filesystem::remove(path);
}

TEST_CASE("demo_files_over_each_limit_are_refused_and_files_at_it_load", "[unit]") {
  // Every limit, made small so that reaching it is cheap; one file just under, one just over.
  DemoFileLimits limits;
  limits.max_demos = 3;
  limits.max_poses_per_demo = 4;
  limits.max_poses = 6;
  limits.max_json_depth = 4;  // a record's own depth
  const std::string path = test::limits_temp_path("small_limits.jsonl");
  const auto file = [](std::size_t count, const std::vector<std::size_t>& poses) {
    std::string text = R"({"clearance":0.1,"count":)" + std::to_string(count) +
                       R"(,"format":"handcentric-demos","version":1})"
                       "\n";
    for (std::size_t n : poses) text += record_of(n);
    return text;
  };
  write_bytes(path, file(3, {2, 2, 2}));
  CHECK(load_in_child(path, limits).out == "loaded 3");
  write_bytes(path, file(4, {1, 1, 1, 1}));
  check_refused(load_in_child(path, limits), "line 1 (header)",
                "4 demos, more than the limit of 3");
  write_bytes(path, file(1, {5}));
  check_refused(load_in_child(path, limits), "record 1",
                "a demo of 5 poses, more than the limit of 4");
  write_bytes(path, file(2, {4, 3}));
  check_refused(load_in_child(path, limits), "record 2",
                "7 poses, more than the limit of 6 for one file");
  write_bytes(path, kHeaderOfOne + "\n" +
                        R"({"world_T_hole":[[[[1]]]],"world_T_hand":[]})"
                        "\n");
  check_refused(load_in_child(path, limits), "record 1", "nested deeper than 4 levels");
  limits.max_line_bytes = record_of(2).size() - 1;  // the line without its newline fits exactly
  write_bytes(path, file(1, {2}));
  CHECK(load_in_child(path, limits).out == "loaded 1");
  limits.max_line_bytes -= 1;
  check_refused(load_in_child(path, limits), "record 1",
                "longer than " + std::to_string(limits.max_line_bytes));
  std::filesystem::remove(path);
}
