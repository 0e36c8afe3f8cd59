// Scene distributions: ranges, determinism, and the OOD set as a global transform of the train set.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>

#include "handcentric/core/errors.hpp"
#include "handcentric//core/sampling.hpp"
#include "handcentric/sim/difficulty.hpp"
#include "handcentric/sim/geometry.hpp"
#include "handcentric/sim/scenes.hpp"
#include "worst_error.hpp"  // tests/support

using namespace handcentric;
using namespace handcentric::sim;

namespace {

double degrees(double radians) {
  return radians * 180.0 / std::numbers::pi;
}

/// The angle in (-180, 180] of a hole angle in degrees.
double wrap_deg(double deg) {
  deg = std::remainder(deg, 360.0);
  return deg <= -180.0 ? deg + 360.0 : deg;
}

using Sampler = TaskScene (*)(const SceneDistribution&, std::uint64_t, std::uint64_t);

// A planted fault: draws the start in the world frame (around the hole's position, not turned
// with it), so OOD starts are not transformed train starts.
TaskScene start_in_world_frame(const SceneDistribution& distribution, std::uint64_t seed,
                               std::uint64_t index) {
  TaskScene scene = sample_scene(distribution, seed, index);
  const RigidTransform hole_T_hand = scene.world_T_hole.inverse_compose(scene.world_T_hand_start);
  const Eigen::Vector3d& p = scene.world_T_hole.translation();
  scene.world_T_hand_start = RigidTransform::planar(0.0, p.x(), p.y()) * hole_T_hand;
  return scene;
}

/// Claim: OOD scene i = g_i * train scene i with g_i = world_T_hole_ood * world_T_hole_train^{-1},
/// to rounding; returns the largest pose error.
double ood_is_a_global_transform_of_train(Sampler sample, int n) {
  double worst = 0.0;
  for (int i = 0; i < n; ++i) {
    const TaskScene train = sample(SceneDistribution::train(), 5, static_cast<std::uint64_t>(i));
    const TaskScene ood = sample(SceneDistribution::ood(), 5, static_cast<std::uint64_t>(i));
    const RigidTransform g = ood.world_T_hole * train.world_T_hole.inverse();
    const TaskScene moved = g * train;
    worst = test::worst_of(worst, distance(moved.world_T_hole, ood.world_T_hole));
    worst = test::worst_of(worst, distance(moved.world_T_hand_start, ood.world_T_hand_start));
  }
  return worst;
}

}  // namespace

TEST_CASE("every_ood_scene_is_a_global_transform_of_a_train_scene", "[property]") {
  CHECK(ood_is_a_global_transform_of_train(sample_scene, 500) < 1e-12);
}

TEST_CASE("mutant_start_drawn_in_the_world_frame_is_caught", "[property]") {
  CHECK(ood_is_a_global_transform_of_train(start_in_world_frame, 500) > 1.0);
}

TEST_CASE("scenes_respect_the_issue_ranges", "[property]") {
  int up = 0, sideways_plus = 0, sideways_minus = 0;
  const int n = 2000;
  for (const auto& scene : sample_scenes(SceneDistribution::train(), n, 3)) {
    const Eigen::Vector3d rel =
        planar_coordinates(scene.world_T_hole.inverse_compose(scene.world_T_hand_start));
    CHECK(std::abs(rel(1)) <= kStartMaxAbsX);
    CHECK((rel(2) >= kStartMinY && rel(2) <= kStartMaxY));
    CHECK(std::abs(degrees(rel(0))) <= kStartMaxAbsAngleDeg + 1e-9);
    const Eigen::Vector3d hole = planar_coordinates(scene.world_T_hole);
    CHECK((std::abs(hole(1)) <= kWorkspaceHalfWidth && std::abs(hole(2)) <= kWorkspaceHalfWidth));
    const double angle = degrees(hole(0));
    if (std::abs(angle) <= 10.0 + 1e-9)
      ++up;
    else if (std::abs(angle - 90.0) <= 10.0 + 1e-9)
      ++sideways_plus;
    else if (std::abs(angle + 90.0) <= 10.0 + 1e-9)
      ++sideways_minus;
    else
      FAIL("train hole angle " << angle << " deg is outside up / sideways");
  }
  // half up, a quarter each side: 4 sigma of a binomial
  CHECK(std::abs(up - n / 2) < 4.0 * std::sqrt(n * 0.25));
  CHECK(std::abs(sideways_plus - n / 4) < 4.0 * std::sqrt(n * 0.1875));
  CHECK(std::abs(sideways_minus - n / 4) < 4.0 * std::sqrt(n * 0.1875));
  for (const auto& scene : sample_scenes(SceneDistribution::ood(), 500, 3)) {
    CHECK(std::abs(std::abs(wrap_deg(degrees(planar_coordinates(scene.world_T_hole)(0)))) -
                   180.0) <= 10.0 + 1e-9);
  }
  for (const auto& scene : sample_scenes(SceneDistribution::parse("30:45"), 500, 3)) {
    const double angle = degrees(planar_coordinates(scene.world_T_hole)(0));
    CHECK((angle >= 30.0 - 1e-9 && angle <= 45.0 + 1e-9));
  }
}

TEST_CASE("the_same_seed_gives_the_same_scenes_bit_for_bit", "[unit]") {
  const auto a = sample_scenes(SceneDistribution::train(), 50, 11);
  const auto b = sample_scenes(SceneDistribution::train(), 50, 11);
  const auto c = sample_scenes(SceneDistribution::train(), 50, 12);
  int differ = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    CHECK(a[i].world_T_hole.matrix() == b[i].world_T_hole.matrix());
    CHECK(a[i].world_T_hand_start.matrix() == b[i].world_T_hand_start.matrix());
    differ += a[i].world_T_hole.matrix() != c[i].world_T_hole.matrix();
  }
  CHECK(differ == 50);
  // scene i does not depend on how many scenes are drawn
  CHECK(sample_scene(SceneDistribution::train(), 11, 49).world_T_hole.matrix() ==
        a[49].world_T_hole.matrix());
}

TEST_CASE("bad_distribution_names_are_rejected_with_the_forms", "[unit]") {
  CHECK_THROWS_WITH(SceneDistribution::parse("sideways"),
                    Catch::Matchers::Contains("sideways") && Catch::Matchers::Contains("A:B"));
  CHECK_THROWS_AS(SceneDistribution::parse("10:-10"), InvalidArgument);
  CHECK_THROWS_AS(SceneDistribution::parse("nan:3"), InvalidArgument);
  CHECK_THROWS_AS(SceneDistribution::parse("1:2:3"), InvalidArgument);
  CHECK_THROWS_AS(sample_scenes(SceneDistribution::train(), -1, 1), InvalidArgument);
  CHECK(SceneDistribution::parse("-10:10").hole_angles.size() == 1);
}

TEST_CASE("a_scene_set_can_be_moved_by_any_global_planar_transform", "[unit]") {
  const RigidTransform g = parse_planar_transform("90,10,-5");
  CHECK(distance(g, RigidTransform::planar(std::numbers::pi / 2.0, 10.0, -5.0)) < 1e-15);
  const auto scenes = sample_scenes(SceneDistribution::train(), 5, 1);
  const auto moved = transform_scenes(g, scenes);
  REQUIRE(moved.size() == scenes.size());
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    CHECK(moved[i].world_T_hole.matrix() == (g * scenes[i].world_T_hole).matrix());
    CHECK(moved[i].world_T_hand_start.matrix() == (g * scenes[i].world_T_hand_start).matrix());
  }
  for (const char* bad : {"90,10", "90,10,-5,1", "a,b,c", "90,nan,0", "", "90,,0"}) {
    INFO(bad);
    CHECK_THROWS_WITH(parse_planar_transform(bad), Catch::Matchers::Contains("DEG,X,Y"));
  }
}

namespace {

/// The largest |x| or |y| of the hole openings of `n` scenes of `distribution`.
double widest_opening(const SceneDistribution& distribution, int n) {
  double widest = 0.0;
  for (const auto& scene : sample_scenes(distribution, n, 3)) {
    const Eigen::Vector3d hole = planar_coordinates(scene.world_T_hole);
    widest = test::worst_of(test::worst_of(widest, std::abs(hole(1))), std::abs(hole(2)));
  }
  return widest;
}

}  // namespace

TEST_CASE("a_smaller_workspace_places_every_hole_inside_it_and_keeps_the_relative_starts",
          "[property]") {
  const Difficulty quarter{25.0, kDefaultClearance};
  const SceneDistribution narrow = quarter.apply(SceneDistribution::train());
  CHECK(widest_opening(narrow, 1000) <= 12.5);
  // The planted fault, the distribution without the workspace: its holes leave the 25 cm square.
  CHECK(widest_opening(SceneDistribution::train(), 1000) > 40.0);
  // Scene i keeps its start relative to the hole and its hole angle: only the position shrinks,
  // so a hand-centric policy meets the same problems in every workspace.
  for (std::uint64_t i = 0; i < 200; ++i) {
    const TaskScene wide = sample_scene(SceneDistribution::train(), 7, i);
    const TaskScene small = sample_scene(narrow, 7, i);
    CHECK(distance(wide.world_T_hole.inverse_compose(wide.world_T_hand_start),
                   small.world_T_hole.inverse_compose(small.world_T_hand_start)) < 1e-12);
    CHECK(planar_coordinates(wide.world_T_hole)(0) == planar_coordinates(small.world_T_hole)(0));
  }
  // The default difficulty is the paper's task, bit for bit.
  const auto before = sample_scenes(SceneDistribution::train(), 20, 5);
  const auto after = sample_scenes(Difficulty{}.apply(SceneDistribution::train()), 20, 5);
  for (std::size_t i = 0; i < before.size(); ++i)
    CHECK(before[i].world_T_hole.matrix() == after[i].world_T_hole.matrix());
}

TEST_CASE("a_bad_difficulty_is_refused_naming_the_value", "[unit]") {
  CHECK_THROWS_WITH(
      (Difficulty{0.5, 0.1}.validate()),
      Catch::Matchers::Contains("--workspace 0.5") && Catch::Matchers::Contains("[1, 1000]"));
  CHECK_THROWS_AS((Difficulty{std::nan(""), 0.1}.validate()), InvalidArgument);
  CHECK_THROWS_WITH((Difficulty{100.0, 0.0}.validate()),
                    Catch::Matchers::Contains("--clearance 0"));
  CHECK_THROWS_AS((Difficulty{100.0, kPegWidth}.validate()), InvalidArgument);
  CHECK_THROWS_AS((Difficulty{100.0, -1.0}.geometry()), InvalidArgument);
  CHECK(Difficulty{}.is_default());
  CHECK_FALSE((Difficulty{50.0, 0.1}.is_default()));
  CHECK((Difficulty{100.0, 0.3}.geometry().clearance == 0.3));
  SceneDistribution broken = SceneDistribution::train();
  broken.workspace_half_width = -1.0;
  CHECK_THROWS_WITH(sample_scene(broken, 1, 0), Catch::Matchers::Contains("half-width -1"));
}
