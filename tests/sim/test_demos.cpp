// Demo files (JSON Lines): exact round trip, atomic writes, and a clear error with the record
// number for every kind of bad file; training scenes as the policy issue reads them.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "handcentric/sim/collision.hpp"
#include "handcentric/sim/demos.hpp"
#include "handcentric/sim/expert.hpp"
#include "handcentric/sim/scenes.hpp"
#include "throws.hpp"

using namespace handcentric;
using namespace handcentric::sim;
using Catch::Matchers::Contains;

namespace {

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("handcentric_test_sim_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

std::vector<Demo> some_demos(int n) {
  const CollisionChecker checker;
  return expert_demos(sample_scenes(SceneDistribution::train(), n, 7), 7, checker).demos;
}

std::string read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

void write(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

/// The file `good` with line `line` (0 = header) replaced by `replacement`.
std::string with_line(const std::string& good, int line, const std::string& replacement) {
  std::istringstream in(good);
  std::string out, text;
  for (int i = 0; std::getline(in, text); ++i) out += (i == line ? replacement : text) + "\n";
  return out;
}

bool same_bits(const RigidTransform& a, const RigidTransform& b) { return a.matrix() == b.matrix(); }

}  // namespace

TEST_CASE("saved_demos_load_back_bit_for_bit", "[unit]") {
  const auto demos = some_demos(3);
  REQUIRE(demos.size() == 3);
  const std::string path = temp_path("roundtrip.jsonl");
  save_demos(path, demos);
  const auto loaded = load_demos(path);
  REQUIRE(loaded.size() == demos.size());
  for (std::size_t i = 0; i < demos.size(); ++i) {
    CHECK(same_bits(loaded[i].world_T_hole, demos[i].world_T_hole));
    REQUIRE(loaded[i].world_T_hand.size() == demos[i].world_T_hand.size());
    for (std::size_t t = 0; t < demos[i].world_T_hand.size(); ++t) CHECK(same_bits(loaded[i].world_T_hand[t], demos[i].world_T_hand[t]));
  }
  CHECK_FALSE(std::filesystem::exists(path + ".tmp." + std::to_string(::getpid())));  // the temporary is gone
  std::filesystem::remove(path);
}

TEST_CASE("bad_demo_files_give_an_error_naming_the_record", "[unit]") {
  const std::string path = temp_path("bad.jsonl");
  save_demos(path, some_demos(2));
  const std::string good = read(path);
  const auto rejects = [&](const std::string& text, const std::string& record, const std::string& what) {
    write(path, text);
    INFO("expecting '" << record << "' and '" << what << "'");
    CHECK_THROWS_AS(load_demos(path), InvalidDemoFile);
    CHECK_THROWS_WITH(load_demos(path), Contains(record) && Contains(what));
  };
  const std::string hole = "\"world_T_hole\":[[1.0,0.0,0.0,0.0],[0.0,1.0,0.0,0.0],[0.0,0.0,1.0,0.0]]";
  const std::string hand_ok = "[[1.0,0.0,0.0,0.0],[0.0,1.0,0.0,5.0],[0.0,0.0,1.0,0.0]]";
  // NaN: JSON has no NaN, writers give null
  rejects(with_line(good, 2, "{" + hole + ",\"world_T_hand\":[" + hand_ok + ",[[1.0,0.0,0.0,null],[0.0,1.0,0.0,5.0],[0.0,0.0,1.0,0.0]]]}"),
          "record 2", "world_T_hand[1]");
  // wrong shape
  rejects(with_line(good, 1, "{" + hole + ",\"world_T_hand\":[[[1.0,0.0,0.0],[0.0,1.0,0.0],[0.0,0.0,1.0]]]}"), "record 1",
          "4 numbers");
  // not rigid
  rejects(with_line(good, 2, "{" + hole + ",\"world_T_hand\":[[[2.0,0.0,0.0,0.0],[0.0,1.0,0.0,5.0],[0.0,0.0,1.0,0.0]]]}"),
          "record 2", "not a rigid transform");
  // rigid but not planar (tilted out of the plane)
  rejects(with_line(good, 1, "{" + hole + ",\"world_T_hand\":[[[1.0,0.0,0.0,0.0],[0.0,0.0,-1.0,5.0],[0.0,1.0,0.0,0.0]]]}"),
          "record 1", "not a planar pose");
  // truncation: a missing record, a cut line, no final newline
  rejects(good.substr(0, good.find('\n', good.find('\n') + 1) + 1), "record 2", "truncated");
  rejects(good.substr(0, good.size() - 40) + "\n", "record 2", "not valid JSON");
  rejects(good.substr(0, good.size() - 1), "record 2", "no final newline");
  // header
  rejects(with_line(good, 0, "{\"format\":\"something-else\"}"), "header", "handcentric-demos");
  rejects(with_line(good, 0, "{\"format\":\"handcentric-demos\",\"version\":9,\"count\":2}"), "header", "version 9");
  // mistyped fields are the same typed error, not a JSON library exception
  rejects(with_line(good, 0, "{\"format\":5,\"version\":1,\"count\":2}"), "header", "handcentric-demos");
  rejects(with_line(good, 0, "{\"format\":\"handcentric-demos\",\"version\":\"1\",\"count\":2}"), "header",
          "version \"1\"");
  rejects(with_line(good, 0, "[1,2]"), "header", "handcentric-demos");
  rejects("", "line 1", "empty");
  rejects(good + hand_ok + "\n", "line 4", "extra data");
  std::filesystem::remove(path);
  CHECK_THROWS_WITH(load_demos(path), Contains(path) && Contains("cannot open"));
}

TEST_CASE("saving_to_a_missing_directory_is_a_typed_error_and_leaves_nothing", "[unit]") {
  const std::string path = temp_path("no_such_dir") + "/demos.jsonl";
  CHECK_THROWS_AS(save_demos(path, some_demos(1)), Error);
  CHECK_THROWS_WITH(save_demos(path, some_demos(1)), Contains(path));
  CHECK_THROWS_AS(save_demos(temp_path("empty_demo.jsonl"), {Demo{}}), InvalidArgument);
}

TEST_CASE("training_scenes_pad_history_and_chunk_and_observe_the_opening_from_the_hand", "[unit]") {
  const Demo demo = some_demos(1).front();
  const int T = static_cast<int>(demo.world_T_hand.size());
  const auto scenes = training_scenes(demo, 2, 16);
  REQUIRE(static_cast<int>(scenes.size()) == T);
  const auto pose = [&](int t) { return demo.world_T_hand[static_cast<std::size_t>(std::clamp(t, 0, T - 1))]; };
  for (int t = 0; t < T; ++t) {
    const Scene& scene = scenes[static_cast<std::size_t>(t)];
    REQUIRE(scene.history_length() == 2);
    REQUIRE(scene.chunk_length() == 16);
    for (int h = 0; h <= 2; ++h) CHECK(same_bits(scene.world_T_hand_history[static_cast<std::size_t>(h)], pose(t - h)));
    for (int k = 1; k <= 16; ++k) CHECK(same_bits(scene.world_T_hand_chunk[static_cast<std::size_t>(k - 1)], pose(t + k)));
    CHECK(scene.world_points.empty());
    REQUIRE(scene.hand_points.size() == 2);
    // the corners seen from the hand are the opening's corners in the world
    const Eigen::Vector3d left = pose(t) * scene.hand_points[0];
    const Eigen::Vector3d right = pose(t) * scene.hand_points[1];
    CHECK((left - demo.world_T_hole * Eigen::Vector3d(-1.05, 0, 0)).norm() < 1e-9);
    CHECK((right - demo.world_T_hole * Eigen::Vector3d(1.05, 0, 0)).norm() < 1e-9);
  }
  CHECK_THROWS_AS(training_scenes(demo, -1, 16), InvalidArgument);
  CHECK_THROWS_AS(training_scenes(demo, 2, 0), InvalidArgument);
  CHECK_THROWS_AS(training_scenes(Demo{}, 2, 16), InvalidArgument);
}

TEST_CASE("training_scenes_of_the_first_n_demos_are_theirs_in_demo_order", "[unit]") {
  const std::vector<Demo> demos = some_demos(3);
  const auto all = training_scenes(demos, 0, 4);
  const auto first_two = training_scenes(demos, 0, 4, 2);
  const std::size_t n0 = demos[0].world_T_hand.size(), n1 = demos[1].world_T_hand.size();
  REQUIRE(first_two.size() == n0 + n1);
  REQUIRE(all.size() == n0 + n1 + demos[2].world_T_hand.size());
  // Scene n0 is the start of demo 1 (a loader that skipped or repeated a demo would differ).
  CHECK(same_bits(first_two[n0].world_T_hand_history[0], demos[1].world_T_hand[0]));
  CHECK(same_bits(all.back().world_T_hand_history[0], demos[2].world_T_hand.back()));
  HC_CHECK_THROWS(training_scenes(demos, 0, 4, 4), InvalidArgument, Contains("4 demos") && Contains("only 3"));
  HC_CHECK_THROWS(training_scenes(demos, 0, 4, -1), InvalidArgument, Contains("-1"));
}

TEST_CASE("demo_bytes_in_memory_parse_like_the_file_they_came_from", "[unit]") {
  const std::string path = temp_path("in_memory.jsonl");
  save_demos(path, some_demos(3));
  const std::string bytes = read(path);
  const std::vector<Demo> from_file = load_demos(path);
  const std::vector<Demo> from_memory = parse_demos(bytes, "received demos");
  REQUIRE(from_memory.size() == from_file.size());
  for (std::size_t i = 0; i < from_file.size(); ++i) {
    CHECK(same_bits(from_memory[i].world_T_hole, from_file[i].world_T_hole));
    REQUIRE(from_memory[i].world_T_hand.size() == from_file[i].world_T_hand.size());
    for (std::size_t t = 0; t < from_file[i].world_T_hand.size(); ++t)
      CHECK(same_bits(from_memory[i].world_T_hand[t], from_file[i].world_T_hand[t]));
  }
  // The same checks, the source named as the path would be.
  const std::string truncated = bytes.substr(0, bytes.size() - 1);
  CHECK_THROWS_AS(parse_demos(truncated, "received demos"), InvalidDemoFile);
  CHECK_THROWS_WITH(parse_demos(truncated, "received demos"),
                    Contains("'received demos'") && Contains("record 3") && Contains("final newline"));
  std::filesystem::remove(path);
}
