// Drawings: the outcome colour is where it should be, and PNGs are written atomically.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "handcentric/core/errors.hpp"
#include "handcentric//sim/draw.hpp"
#include "handcentric/sim/policies.hpp"

using namespace handcentric;
using namespace handcentric::sim;

namespace {

int outcome_pixels(const Image& image, const std::uint8_t (&colour)[3]) {
  return image.count_pixels(colour[0], colour[1], colour[2]);
}

}  // namespace

TEST_CASE("a_successful_rollout_is_drawn_green_and_a_collision_red", "[unit]") {
  const CollisionChecker checker;
  const RigidTransform world_T_hole = RigidTransform::planar(2.0, -20.0, 30.0);
  const TaskScene aligned{world_T_hole, world_T_hole * RigidTransform::planar(0.0, 0.0, 15.0)};
  const TaskScene offset{world_T_hole, world_T_hole * RigidTransform::planar(0.0, 3.0, 15.0)};
  const Rollout success = rollout(StraightPolicy(), aligned, checker, 1);
  const Rollout collision = rollout(StraightPolicy(), offset, checker, 1);
  REQUIRE(success.outcome == Outcome::success);
  REQUIRE(collision.outcome == Outcome::collision);
  const Image good = draw_rollout(aligned, success, checker.geometry(), 400);
  const Image bad = draw_rollout(offset, collision, checker.geometry(), 400);
  CHECK(good.width == 400);
  CHECK(good.rgb.size() == 400u * 400u * 3u);
  CHECK(outcome_pixels(good, kSuccessRgb) > 500);  // the final peg, filled
  CHECK(outcome_pixels(good, kCollisionRgb) == 0);
  CHECK(outcome_pixels(bad, kCollisionRgb) > 500);
  CHECK(outcome_pixels(bad, kSuccessRgb) == 0);
}

TEST_CASE("drawings_are_written_as_png_atomically", "[unit]") {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("handcentric_test_draw_" + std::to_string(::getpid()) + ".png"))
                               .string();
  const TaskScene scene = sample_scene(SceneDistribution::train(), 1, 0);
  write_png(path, draw_scene(scene, PegHoleGeometry(), 200));
  std::ifstream in(path, std::ios::binary);
  char magic[8] = {};
  in.read(magic, 8);
  CHECK(std::string(magic + 1, 3) == "PNG");
  std::filesystem::remove(path);
  CHECK_THROWS_AS(write_png("/nonexistent_dir_handcentric/x.png", draw_scene(scene)), Error);
  CHECK_THROWS_AS(draw_scene(scene, PegHoleGeometry(), 10), InvalidArgument);
  CHECK_THROWS_AS(write_png(path, Image{}), InvalidArgument);
}
