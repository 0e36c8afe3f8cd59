// 3D demo files: a round trip gives back the same bits, each file records its task and a file of
// the other task is refused with a one-line message naming both; training scenes carry the
// opening's four corners in the hand frame.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

#include "handcentric/sim/demos.hpp"
#include "handcentric/sim/insert3d/camera.hpp"
#include "handcentric/sim/insert3d/expert.hpp"

using namespace handcentric;
using namespace handcentric::sim::insert3d;

namespace {

std::string insert3d_temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("handcentric_insert3d_" + name)).string();
}

std::vector<Demo> some_demos(int n) {
  const CollisionChecker checker;
  return expert_demos(sample_scenes(SceneDistribution::random_se3(), n, 4), 4, checker).demos;
}

std::string first_line(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

}  // namespace

TEST_CASE("insert3d_demo_files_round_trip_bit_for_bit_and_record_their_task", "[unit]") {
  const std::vector<Demo> demos = some_demos(3);
  REQUIRE(demos.size() == 3u);
  const std::string path = insert3d_temp_path("round_trip.jsonl");
  save_demos(path, demos);
  CHECK_THAT(first_line(path), Catch::Matchers::Contains("\"task\":\"insert3d\"") &&
                                   Catch::Matchers::Contains("\"clearance_per_side\":0.1"));
  const std::vector<Demo> loaded = load_demos(path);
  REQUIRE(loaded.size() == demos.size());
  for (std::size_t i = 0; i < demos.size(); ++i) {
    CHECK(loaded[i].world_T_slot.matrix() == demos[i].world_T_slot.matrix());
    REQUIRE(loaded[i].world_T_hand.size() == demos[i].world_T_hand.size());
    for (std::size_t t = 0; t < demos[i].world_T_hand.size(); ++t) {
      CHECK(loaded[i].world_T_hand[t].matrix() == demos[i].world_T_hand[t].matrix());
    }
  }
  std::filesystem::remove(path);
}

TEST_CASE("insert3d_and_2d_demo_files_are_not_mixed_up", "[unit]") {
  const std::string path3d = insert3d_temp_path("mix3d.jsonl");
  save_demos(path3d, some_demos(1));
  CHECK_THROWS_WITH(sim::load_demos(path3d),
                    Catch::Matchers::Contains("task 'insert3d', not 'peg2d'") &&
                        Catch::Matchers::Contains("--task insert3d"));
  const std::string path2d = insert3d_temp_path("mix2d.jsonl");
  sim::save_demos(path2d, {sim::Demo{RigidTransform(), {RigidTransform::planar(0.1, 1.0, 2.0)}}});
  CHECK_THAT(first_line(path2d), Catch::Matchers::Contains("\"task\":\"peg2d\""));
  CHECK_THROWS_AS(load_demos(path2d), sim::InvalidDemoFile);
  CHECK_THROWS_WITH(load_demos(path2d), Catch::Matchers::Contains("task 'peg2d', not 'insert3d'"));
  // a 2D file written before files named their task is still a 2D file
  {
    std::ofstream out(path2d);
    out << R"({"clearance":0.1,"count":0,"format":"handcentric-demos","version":1})"
        << "\n";
  }
  CHECK(sim::load_demos(path2d).empty());
  CHECK_THROWS_WITH(load_demos(path2d), Catch::Matchers::Contains("task 'peg2d'"));
  std::filesystem::remove(path3d);
  std::filesystem::remove(path2d);
}

TEST_CASE("insert3d_training_scenes_see_the_four_opening_corners", "[unit]") {
  const std::vector<Demo> demos = some_demos(2);
  const std::vector<Scene> scenes = training_scenes(demos, 2, 16);
  CHECK(scenes.size() == demos[0].world_T_hand.size() + demos[1].world_T_hand.size());
  const BladeSlotGeometry geometry;
  const Scene& last = scenes.back();
  REQUIRE(last.hand_points.size() == 4u);
  REQUIRE(last.history_length() == 2);
  REQUIRE(last.chunk_length() == 16);
  const auto corners =
      opening_corners_in_hand(geometry, last.world_T_hand0(), demos[1].world_T_slot);
  for (std::size_t k = 0; k < 4; ++k) CHECK((last.hand_points[k] - corners[k]).norm() == 0.0);
  CHECK_THROWS_AS(training_scenes(demos, 0, 16, 3), InvalidArgument);
}
