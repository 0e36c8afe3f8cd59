// Demo files (JSON Lines): exact round trip, atomic writes, and a clear error with the record
// number for every kind of bad file; training scenes as the policy issue reads them.
#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <numbers>
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
  return (std::filesystem::temp_directory_path() /
          ("handcentric_test_sim_" + std::to_string(::getpid()) + "_" + name))
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

void write(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

/// The file `good` with line `line` (0 = header) replaced by `replacement`.
std::string with_line(const std::string& good, int line, const std::string& replacement) {
  std::istringstream in(good);
  std::string out, text;
  for (int i = 0; std::getline(in, text); ++i) out += (i == line ? replacement : text) + "\n";
  return out;
}

bool same_bits(const RigidTransform& a, const RigidTransform& b) {
  return a.matrix() == b.matrix();
}

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
    for (std::size_t t = 0; t < demos[i].world_T_hand.size(); ++t)
      CHECK(same_bits(loaded[i].world_T_hand[t], demos[i].world_T_hand[t]));
  }
  CHECK_FALSE(std::filesystem::exists(path + ".tmp." +
                                      std::to_string(::getpid())));  // the temporary is gone
  std::filesystem::remove(path);
}

TEST_CASE("a_demo_file_gives_back_the_hole_it_was_made_with", "[unit]") {
  const auto demos = some_demos(1);
  REQUIRE(demos.size() == 1);
  const std::string path = temp_path("clearance.jsonl");
  PegHoleGeometry wide;
  wide.clearance = 0.3;
  save_demos(path, demos, wide);
  CHECK(demo_file_geometry(path).clearance == 0.3);
  const std::string good = read(path);
  // A header written without the clearance is the paper's hole.
  write(path, with_line(good, 0, R"({"format": "handcentric-demos", "version": 1, "count": 1})"));
  CHECK(demo_file_geometry(path).clearance == kDefaultClearance);
  for (const char* bad : {"-1", "\"wide\"", "2.5"}) {
    write(path, with_line(good, 0,
                          std::string(R"({"format": "handcentric-demos", "version": 1, )") +
                              R"("count": 1, "clearance": )" + bad + "}"));
    CHECK_THROWS_AS(demo_file_geometry(path), InvalidDemoFile);
    CHECK_THROWS_WITH(demo_file_geometry(path),
                      Contains(std::string("\"clearance\" ") + bad) && Contains(path));
  }
  std::filesystem::remove(path);
}

TEST_CASE("bad_demo_files_give_an_error_naming_the_record", "[unit]") {
  const std::string path = temp_path("bad.jsonl");
  save_demos(path, some_demos(2));
  const std::string good = read(path);
  const auto rejects = [&](const std::string& text, const std::string& record,
                           const std::string& what) {
    write(path, text);
    INFO("expecting '" << record << "' and '" << what << "'");
    CHECK_THROWS_AS(load_demos(path), InvalidDemoFile);
    CHECK_THROWS_WITH(load_demos(path), Contains(record) && Contains(what));
  };
  const std::string hole =
      "\"world_T_hole\":[[1.0,0.0,0.0,0.0],[0.0,1.0,0.0,0.0],[0.0,0.0,1.0,0.0]]";
  const std::string hand_ok = "[[1.0,0.0,0.0,0.0],[0.0,1.0,0.0,5.0],[0.0,0.0,1.0,0.0]]";
  // NaN: JSON has no NaN, writers give null
  rejects(with_line(good, 2,
                    "{" + hole + ",\"world_T_hand\":[" + hand_ok +
                        ",[[1.0,0.0,0.0,null],[0.0,1.0,0.0,5.0],[0.0,0.0,1.0,0.0]]]}"),
          "record 2", "world_T_hand[1]");
  // wrong shape
  rejects(
      with_line(good, 1,
                "{" + hole + ",\"world_T_hand\":[[[1.0,0.0,0.0],[0.0,1.0,0.0],[0.0,0.0,1.0]]]}"),
      "record 1", "4 numbers");
  // not rigid
  rejects(
      with_line(good, 2,
                "{" + hole +
                    ",\"world_T_hand\":[[[2.0,0.0,0.0,0.0],[0.0,1.0,0.0,5.0],[0.0,0.0,1.0,0.0]]]}"),
      "record 2", "not a rigid transform");
  // rigid but not planar (tilted out of the plane)
  rejects(with_line(
              good, 1,
              "{" + hole +
                  ",\"world_T_hand\":[[[1.0,0.0,0.0,0.0],[0.0,0.0,-1.0,5.0],[0.0,1.0,0.0,0.0]]]}"),
          "record 1", "not a planar pose");
  // truncation: a missing record, a cut line, no final newline
  rejects(good.substr(0, good.find('\n', good.find('\n') + 1) + 1), "record 2", "truncated");
  rejects(good.substr(0, good.size() - 40) + "\n", "record 2", "not valid JSON");
  rejects(good.substr(0, good.size() - 1), "record 2", "no final newline");
  // header
  rejects(with_line(good, 0, "{\"format\":\"something-else\"}"), "header", "handcentric-demos");
  rejects(with_line(good, 0, "{\"format\":\"handcentric-demos\",\"version\":9,\"count\":2}"),
          "header", "version 9");
  // mistyped fields are the same typed error, not a JSON library exception
  rejects(with_line(good, 0, "{\"format\":5,\"version\":1,\"count\":2}"), "header",
          "handcentric-demos");
  rejects(with_line(good, 0, "{\"format\":\"handcentric-demos\",\"version\":\"1\",\"count\":2}"),
          "header", "version \"1\"");
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
  const auto pose = [&](int t) {
    return demo.world_T_hand[static_cast<std::size_t>(std::clamp(t, 0, T - 1))];
  };
  for (int t = 0; t < T; ++t) {
    const Scene& scene = scenes[static_cast<std::size_t>(t)];
    REQUIRE(scene.history_length() == 2);
    REQUIRE(scene.chunk_length() == 16);
    for (int h = 0; h <= 2; ++h)
      CHECK(same_bits(scene.world_T_hand_history[static_cast<std::size_t>(h)], pose(t - h)));
    for (int k = 1; k <= 16; ++k)
      CHECK(same_bits(scene.world_T_hand_chunk[static_cast<std::size_t>(k - 1)], pose(t + k)));
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
  HC_CHECK_THROWS(training_scenes(demos, 0, 4, 4), InvalidArgument,
                  Contains("4 demos") && Contains("only 3"));
  HC_CHECK_THROWS(training_scenes(demos, 0, 4, -1), InvalidArgument, Contains("-1"));
}

namespace {

// What a mirror image of a demo must be: every pose and every motion free of collision, the peg
// inserted at the end, each eye-in-hand observation the reflection (x -> -x, left and right
// corners swapped) of the original's, and the mirror of the mirror the original. Returns the
// first violation, empty when there is none.
std::string mirror_violation(const Demo& demo, const Demo& mirrored) {
  const CollisionChecker checker;
  if (mirrored.world_T_hand.size() != demo.world_T_hand.size())
    return "a different number of poses";
  for (std::size_t t = 0; t < demo.world_T_hand.size(); ++t) {
    const RigidTransform hole_T_hand =
        mirrored.world_T_hole.inverse_compose(mirrored.world_T_hand[t]);
    if (checker.collides(hole_T_hand)) return "pose " + std::to_string(t) + " collides";
    if (t > 0 &&
        checker.motion_collides(mirrored.world_T_hole.inverse_compose(mirrored.world_T_hand[t - 1]),
                                hole_T_hand)) {
      return "the motion into pose " + std::to_string(t) + " collides";
    }
    const auto seen = eye_in_hand_points(demo.world_T_hole, demo.world_T_hand[t]);
    const auto seen_mirrored = eye_in_hand_points(mirrored.world_T_hole, mirrored.world_T_hand[t]);
    for (int i = 0; i < 2; ++i) {
      const Eigen::Vector3d reflected(-seen[1 - i].x(), seen[1 - i].y(), seen[1 - i].z());
      if ((seen_mirrored[i] - reflected).norm() > 1e-9)
        return "observation " + std::to_string(t) + " is not reflected";
    }
  }
  const RigidTransform hole_T_end =
      mirrored.world_T_hole.inverse_compose(mirrored.world_T_hand.back());
  if ((hole_T_end * Eigen::Vector3d(0, -kPegLength, 0)).y() > -kSuccessDepth)
    return "the peg is not inserted";
  return "";
}

}  // namespace

TEST_CASE("a_demo_mirrored_about_its_hole_axis_is_another_valid_insertion", "[unit]") {
  const std::vector<Demo> demos = some_demos(6);
  REQUIRE(demos.size() == 6);
  const std::vector<Demo> all = with_mirrored_demos(demos);
  REQUIRE(all.size() == 12);
  for (std::size_t i = 0; i < demos.size(); ++i) {
    INFO("demo " << i);
    CHECK(mirror_violation(demos[i], all[6 + i]).empty());
    CHECK(same_bits(all[i].world_T_hand.back(), demos[i].world_T_hand.back()));
    const Demo twice = mirrored_about_hole_axis(all[6 + i]);
    for (std::size_t t = 0; t < twice.world_T_hand.size(); ++t) {
      CHECK((twice.world_T_hand[t].matrix() - demos[i].world_T_hand[t].matrix()).norm() < 1e-9);
    }
  }
  HC_CHECK_THROWS(mirrored_about_hole_axis(Demo()), InvalidArgument, Contains("no hand pose"));
}

TEST_CASE("mutant_a_mirror_that_keeps_the_angle_is_caught", "[unit]") {
  // Planted fault: x negated but the angle kept, a pose no reflection gives.
  const std::vector<Demo> demos = some_demos(3);
  int caught = 0;
  for (const Demo& demo : demos) {
    Demo wrong = demo;
    for (RigidTransform& world_T_hand : wrong.world_T_hand) {
      const RigidTransform hole_T_hand = demo.world_T_hole.inverse_compose(world_T_hand);
      const Eigen::Matrix3d& R = hole_T_hand.rotation().matrix();
      world_T_hand = demo.world_T_hole * RigidTransform::planar(std::atan2(R(1, 0), R(0, 0)),
                                                                -hole_T_hand.translation().x(),
                                                                hole_T_hand.translation().y());
    }
    if (!mirror_violation(demo, wrong).empty()) ++caught;
  }
  CHECK(caught == 3);
}

TEST_CASE("training_data_adds_the_mirror_images_after_the_demos_by_default", "[unit]") {
  const std::vector<Demo> demos = some_demos(3);
  const std::vector<Scene> plain = training_scenes(demos, 0, 4, 2);
  TrainingData recipe;
  recipe.perturbed_copies = 0;  // the copies have their own tests below
  const std::vector<Scene> mirrored = training_scenes(demos, 0, 4, 2, recipe);
  REQUIRE(TrainingData().mirror);
  REQUIRE(mirrored.size() == 2 * plain.size());
  CHECK(TrainingData().samples(static_cast<long long>(plain.size())) ==
        static_cast<long long>(mirrored.size()));
  for (std::size_t i = 0; i < plain.size(); ++i)
    CHECK(same_bits(mirrored[i].world_T_hand0(), plain[i].world_T_hand0()));
  const std::vector<Scene> of_mirrors =
      training_scenes(with_mirrored_demos({demos[0], demos[1]}), 0, 4, 0);
  for (std::size_t i = plain.size(); i < mirrored.size(); ++i) {
    CHECK(same_bits(mirrored[i].world_T_hand0(), of_mirrors[i].world_T_hand0()));
  }
  TrainingData off = recipe;
  off.mirror = false;
  CHECK(training_scenes(demos, 0, 4, 2, off).size() == plain.size());
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
  CHECK_THROWS_WITH(parse_demos(truncated, "received demos"), Contains("'received demos'") &&
                                                                  Contains("record 3") &&
                                                                  Contains("final newline"));
  std::filesystem::remove(path);
}

namespace {

// A perturbed copy (TrainingData::perturbed_copies) must be a feasible recovery onto the demo:
// the moved hand and every motion of its chunk free of the hole, the chunk back on the demo's
// own poses from recovery_steps on, the observation seen from the moved hand, the offset within
// its bounds. Returns the first violation, empty when there is none.
std::string recovery_violation(const Scene& copy, const Demo& demo, const TrainingData& data) {
  const CollisionChecker checker;
  const auto hole_T = [&](const RigidTransform& world_T_hand) {
    return demo.world_T_hole.inverse_compose(world_T_hand);
  };
  const RigidTransform& world_T_moved = copy.world_T_hand_history.front();
  if (checker.collides(hole_T(world_T_moved))) return "the moved hand touches the hole";
  RigidTransform previous = world_T_moved;
  for (const RigidTransform& world_T_next : copy.world_T_hand_chunk) {
    if (checker.motion_collides(hole_T(previous), hole_T(world_T_next)))
      return "a motion of the chunk touches the hole";
    previous = world_T_next;
  }
  // The demo step t whose future the chunk rejoins: chunk[k - 1] = T_{t+k} for k >= recovery_steps.
  const int T = static_cast<int>(demo.world_T_hand.size());
  const int K = static_cast<int>(copy.world_T_hand_chunk.size());
  const auto demo_pose = [&](int t) {
    return demo.world_T_hand[static_cast<std::size_t>(std::clamp(t, 0, T - 1))];
  };
  int rejoined_at = -1;
  for (int t = 0; t < T && rejoined_at < 0; ++t) {
    bool same = true;
    for (int k = data.recovery_steps; k <= K && same; ++k) {
      same = (copy.world_T_hand_chunk[static_cast<std::size_t>(k - 1)].matrix() -
              demo_pose(t + k).matrix())
                 .norm() < 1e-9;
    }
    if (same) rejoined_at = t;
  }
  if (rejoined_at < 0) return "the chunk does not return to the demo's poses";
  const RigidTransform offset =
      hole_T(demo_pose(rejoined_at)).inverse_compose(hole_T(world_T_moved));
  // drawn in the hole's frame (x, y each within offset_cm): at most sqrt(2) offset_cm long
  if (offset.translation().norm() > std::sqrt(2.0) * data.offset_cm + 1e-9)
    return "the offset is out of bounds";
  if (offset.rotation().angle() > data.offset_deg * std::numbers::pi / 180.0 + 1e-9)
    return "the angle offset is out of bounds";
  const auto seen = eye_in_hand_points(demo.world_T_hole, world_T_moved);
  for (std::size_t i = 0; i < seen.size(); ++i) {
    if ((seen[i] - copy.hand_points[i]).norm() > 1e-12)
      return "the observation is not the moved hand's";
  }
  return "";
}

TrainingData with_copies(int copies) {
  TrainingData data;
  data.mirror = false;
  data.perturbed_copies = copies;
  return data;
}

}  // namespace

TEST_CASE("perturbed_copies_are_feasible_recoveries_onto_their_demo", "[unit]") {
  const std::vector<Demo> demos = some_demos(3);
  const TrainingData data = with_copies(3);
  const std::vector<Scene> plain = training_scenes(demos, 0, 16, 0);
  const std::vector<Scene> all = training_scenes(demos, 0, 16, 0, data);
  REQUIRE(all.size() > plain.size());
  CHECK(all.size() <= 4 * plain.size());  // copies that touch the hole are dropped
  for (std::size_t i = 0; i < plain.size(); ++i)
    CHECK(same_bits(all[i].world_T_hand0(), plain[i].world_T_hand0()));
  // The copies come demo after demo; each is checked against the demo whose future it rejoins.
  int checked = 0;
  for (std::size_t i = plain.size(); i < all.size(); ++i) {
    std::string violation = "no demo";
    for (const Demo& demo : demos) {
      violation = recovery_violation(all[i], demo, data);
      if (violation.empty() || violation != "the chunk does not return to the demo's poses") break;
    }
    INFO("copy " << i - plain.size());
    CHECK(violation.empty());
    ++checked;
  }
  CHECK(checked >
        static_cast<int>(plain.size()));  // most copies are kept: ~3 per sample, ~1/3 dropped
  // the same seed gives the same bits, another seed other copies
  const std::vector<Scene> again = training_scenes(demos, 0, 16, 0, data);
  REQUIRE(again.size() == all.size());
  for (std::size_t i = 0; i < all.size(); ++i)
    CHECK(same_bits(again[i].world_T_hand0(), all[i].world_T_hand0()));
  TrainingData other = data;
  other.perturbation_seed = 2;
  CHECK_FALSE(same_bits(training_scenes(demos, 0, 16, 0, other).back().world_T_hand0(),
                        all.back().world_T_hand0()));
}

TEST_CASE("mutant_a_copy_that_never_returns_to_its_demo_is_caught", "[unit]") {
  // Planted faults on real copies: the whole chunk shifted by the offset for good (no recovery),
  // and a copy moved into the wall.
  const std::vector<Demo> demos = some_demos(1);
  const TrainingData data = with_copies(2);
  const std::vector<Scene> plain = training_scenes(demos, 0, 16, 0);
  const std::vector<Scene> all = training_scenes(demos, 0, 16, 0, data);
  REQUIRE(all.size() > plain.size() + 10);
  int caught_drift = 0, caught_wall = 0;
  for (std::size_t i = plain.size(); i < plain.size() + 10; ++i) {
    REQUIRE(recovery_violation(all[i], demos[0], data).empty());
    Scene drifting = all[i];
    const RigidTransform shift = RigidTransform::planar(0.0, 0.3, 0.0);
    for (RigidTransform& world_T_hand : drifting.world_T_hand_chunk)
      world_T_hand = world_T_hand * shift;
    if (!recovery_violation(drifting, demos[0], data).empty()) ++caught_drift;
    Scene in_wall = all[i];
    in_wall.world_T_hand_history.front() =
        demos[0].world_T_hole * RigidTransform::planar(0.0, 3.0, -0.5);
    if (!recovery_violation(in_wall, demos[0], data).empty()) ++caught_wall;
  }
  CHECK(caught_drift == 10);
  CHECK(caught_wall == 10);
}

TEST_CASE("bad_training_data_recipes_are_typed_errors_naming_the_field", "[unit]") {
  const std::vector<Demo> demos = some_demos(1);
  TrainingData data = with_copies(-1);
  HC_CHECK_THROWS(training_scenes(demos, 0, 4, 0, data), InvalidArgument,
                  Contains("perturbed_copies") && Contains("-1"));
  data = with_copies(1);
  data.offset_cm = std::nan("");
  HC_CHECK_THROWS(training_scenes(demos, 0, 4, 0, data), InvalidArgument, Contains("offset_cm"));
  data = with_copies(1);
  data.recovery_steps = 0;
  HC_CHECK_THROWS(training_scenes(demos, 0, 4, 0, data), InvalidArgument,
                  Contains("recovery_steps"));
}
