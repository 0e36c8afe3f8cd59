// The trajectory-optimization expert: solves the scenes, valid demos, equivariant by construction,
// deterministic.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <random>

#include "handcentric/core/errors.hpp"
#include "handcentric//core/sampling.hpp"
#include "handcentric/sim/expert.hpp"
#include "handcentric/sim/rollout.hpp"
#include "worst_error.hpp"  // tests/support

using namespace handcentric;
using namespace handcentric::sim;

namespace {

using DemoMaker = std::vector<RigidTransform> (*)(const TaskScene&, std::uint64_t index,
                                                  const CollisionChecker&);

std::vector<RigidTransform> real_expert(const TaskScene& scene, std::uint64_t index,
                                        const CollisionChecker& checker) {
  const ExpertRun run = expert_demo(scene, 9, index, checker);
  return run.demos.empty() ? std::vector<RigidTransform>{} : run.demos.front().world_T_hand;
}

// A planted fault: plans in a frame at the hole's position but aligned with the world axes.
std::vector<RigidTransform> world_axes_expert(const TaskScene& scene, std::uint64_t index,
                                              const CollisionChecker& checker) {
  const Eigen::Vector3d& p = scene.world_T_hole.translation();
  const RigidTransform world_T_frame = RigidTransform::planar(0.0, p.x(), p.y());
  std::mt19937_64 rng(stream_seed(9, index));
  const ExpertPlan plan =
      plan_in_hole_frame(world_T_frame.inverse_compose(scene.world_T_hand_start), rng, checker);
  std::vector<RigidTransform> out;
  for (const auto& frame_T_hand : plan.hole_T_hand) out.push_back(world_T_frame * frame_T_hand);
  return out;
}

/// Claim: demo(g * scene) = g * demo(scene) for random planar g; returns the largest error.
double equivariance_error(DemoMaker make, int n) {
  const CollisionChecker checker;
  std::mt19937_64 rng(21);
  double worst = 0.0;
  const auto scenes = sample_scenes(SceneDistribution::train(), n, 4);
  for (int i = 0; i < n; ++i) {
    const RigidTransform g =
        RigidTransform::planar(2.0 * std::numbers::pi * uniform01(rng),
                               100.0 * uniform01(rng) - 50.0, 100.0 * uniform01(rng) - 50.0);
    const auto demo =
        make(scenes[static_cast<std::size_t>(i)], static_cast<std::uint64_t>(i), checker);
    const auto moved =
        make(g * scenes[static_cast<std::size_t>(i)], static_cast<std::uint64_t>(i), checker);
    if (demo.size() != moved.size()) return INFINITY;
    for (std::size_t t = 0; t < demo.size(); ++t)
      worst = test::worst_of(worst, distance(moved[t], g * demo[t]));
  }
  return worst;
}

}  // namespace

TEST_CASE("expert_solves_at_least_99_percent_of_train_and_ood_scenes", "[experiment]") {
  const CollisionChecker checker;
  for (const auto& distribution : {SceneDistribution::train(), SceneDistribution::ood()}) {
    const ExpertRun run = expert_demos(sample_scenes(distribution, 300, 1), 1, checker);
    WARN(distribution.name << ": solved " << run.solved_rate() << ", discard rate "
                           << run.discard_rate() << " (" << run.discarded << " of " << run.solutions
                           << " solutions)");
    CHECK(run.solved_rate() >= 0.99);
    CHECK(run.demos.size() == static_cast<std::size_t>(run.scenes - run.unsolved));
  }
}

TEST_CASE("expert_demos_are_collision_free_inserted_and_within_the_step_limits", "[property]") {
  const CollisionChecker checker;
  const auto scenes = sample_scenes(SceneDistribution::parse("-180:180"), 60, 2);
  const ExpertRun run = expert_demos(scenes, 2, checker);
  REQUIRE(run.unsolved == 0);
  for (std::size_t i = 0; i < run.demos.size(); ++i) {
    const Demo& demo = run.demos[i];
    INFO("demo " << i);
    CHECK(demo.world_T_hand.front().matrix() == scenes[i].world_T_hand_start.matrix());
    CHECK(static_cast<int>(demo.world_T_hand.size()) <= kMaxDemoSteps);
    for (std::size_t t = 0; t + 1 < demo.world_T_hand.size(); ++t) {
      const RigidTransform step = demo.world_T_hand[t].inverse_compose(demo.world_T_hand[t + 1]);
      CHECK(step.translation().norm() <= kMaxStepCm);
      CHECK(step.rotation().angle() <= kMaxStepDeg * std::numbers::pi / 180.0);
      CHECK_FALSE(
          checker.motion_collides(demo.world_T_hole.inverse_compose(demo.world_T_hand[t]),
                                  demo.world_T_hole.inverse_compose(demo.world_T_hand[t + 1])));
    }
    CHECK(is_inserted(demo.world_T_hole.inverse_compose(demo.world_T_hand.back())));
  }
}

TEST_CASE("transforming_a_scene_transforms_its_expert_demo", "[property]") {
  CHECK(equivariance_error(real_expert, 40) < 1e-9);
}

TEST_CASE("mutant_expert_planning_in_world_axes_is_caught", "[property]") {
  CHECK(equivariance_error(world_axes_expert, 40) > 1e-3);
}

TEST_CASE("the_same_seed_gives_the_same_demos_bit_for_bit", "[unit]") {
  const CollisionChecker checker;
  const auto scenes = sample_scenes(SceneDistribution::ood(), 20, 6);
  const ExpertRun a = expert_demos(scenes, 6, checker);
  const ExpertRun b = expert_demos(scenes, 6, checker);
  const ExpertRun c = expert_demos(scenes, 7, checker);
  REQUIRE(a.demos.size() == b.demos.size());
  int differ = 0;
  for (std::size_t i = 0; i < a.demos.size(); ++i) {
    REQUIRE(a.demos[i].world_T_hand.size() == b.demos[i].world_T_hand.size());
    for (std::size_t t = 0; t < a.demos[i].world_T_hand.size(); ++t) {
      CHECK(a.demos[i].world_T_hand[t].matrix() == b.demos[i].world_T_hand[t].matrix());
    }
    differ += a.demos[i].world_T_hand.size() != c.demos[i].world_T_hand.size() ||
              a.demos[i].world_T_hand[1].matrix() != c.demos[i].world_T_hand[1].matrix();
  }
  CHECK(differ > 15);  // another seed, other via points: other demos
  CHECK(a.discarded == b.discarded);
}

TEST_CASE("resampling_keeps_the_ends_and_the_step_limits", "[unit]") {
  const std::vector<RigidTransform> path = {
      RigidTransform::planar(0.7, 3.0, 15.0), RigidTransform::planar(-0.2, -2.0, 10.0),
      RigidTransform::planar(0.0, 0.0, 9.0), RigidTransform::planar(0.0, 0.0, 2.5)};
  const auto steps = resample_at_control_step(path);
  CHECK(steps.front().matrix() == path.front().matrix());
  CHECK(steps.back().matrix() == path.back().matrix());
  for (std::size_t t = 0; t + 1 < steps.size(); ++t) {
    const RigidTransform step = steps[t].inverse_compose(steps[t + 1]);
    CHECK(step.translation().norm() <= kMaxStepCm);
    CHECK(step.rotation().angle() <= kMaxStepDeg * std::numbers::pi / 180.0);
  }
  CHECK(steps.size() >=
        2 + static_cast<std::size_t>((std::hypot(5.0, 5.0) + 2.0 + 6.5) / kMaxStepCm) - 2);
  CHECK_THROWS_AS(resample_at_control_step({}), InvalidArgument);
  CHECK_THROWS_AS(resample_at_control_step(path, 0.0), InvalidArgument);
}

TEST_CASE("without_the_collision_term_invalid_solutions_are_discarded_and_counted", "[unit]") {
  // Zero optimizer steps keep the smooth via-point path as it is: some of those clip a wall.
  // Validation must catch them, count them, and retry with another via point.
  const CollisionChecker checker;
  ExpertOptions no_collision_term;
  no_collision_term.iterations = 0;
  const auto scenes = sample_scenes(SceneDistribution::train(), 200, 12);
  const ExpertRun raw = expert_demos(scenes, 12, checker, no_collision_term);
  const ExpertRun optimized = expert_demos(scenes, 12, checker);
  WARN("discard rate without the collision term " << raw.discard_rate() << ", with it "
                                                  << optimized.discard_rate());
  CHECK(raw.discarded > 0);
  CHECK(raw.solutions == raw.discarded + static_cast<int>(raw.demos.size()));
  CHECK(optimized.discarded < raw.discarded);
  for (const Demo& demo : raw.demos) {  // whatever survived is valid
    for (std::size_t t = 0; t + 1 < demo.world_T_hand.size(); ++t) {
      REQUIRE_FALSE(
          checker.motion_collides(demo.world_T_hole.inverse_compose(demo.world_T_hand[t]),
                                  demo.world_T_hole.inverse_compose(demo.world_T_hand[t + 1])));
    }
  }
}

namespace {

// The median, over the demos, of the lateral (cm) and angular (deg) change in the last step
// before the hand first stands on the hole axis upright (the start of the straight insertion).
std::pair<double, double> arrival_jump(const ExpertOptions& options) {
  const CollisionChecker checker;
  const ExpertRun run =
      expert_demos(sample_scenes(SceneDistribution::train(), 60, 21), 21, checker, options);
  std::vector<double> lateral, angular;
  for (const Demo& demo : run.demos) {
    for (std::size_t t = 1; t < demo.world_T_hand.size(); ++t) {
      const Eigen::Vector3d q =
          planar_coordinates(demo.world_T_hole.inverse_compose(demo.world_T_hand[t]));
      if (std::abs(q(0)) > 1e-9 || std::abs(q(1)) > 1e-9) continue;
      const Eigen::Vector3d before =
          planar_coordinates(demo.world_T_hole.inverse_compose(demo.world_T_hand[t - 1]));
      lateral.push_back(std::abs(before(1)));
      angular.push_back(std::abs(before(0)) * 180.0 / std::numbers::pi);
      break;
    }
  }
  REQUIRE(lateral.size() == run.demos.size());
  std::sort(lateral.begin(), lateral.end());
  std::sort(angular.begin(), angular.end());
  return {lateral[lateral.size() / 2], angular[angular.size() / 2]};
}

}  // namespace

TEST_CASE("the_approach_arrives_at_pre_insertion_along_the_hole_axis", "[unit]") {
  // A policy has to reproduce the demos' turn into the hole within the 0.05 cm clearance: the
  // approach must not reach pre-insertion moving sideways and turn down in one step.
  const auto [lateral_cm, angle_deg] = arrival_jump(ExpertOptions());
  INFO("median last approach step: " << lateral_cm << " cm sideways, " << angle_deg << " deg");
  CHECK(lateral_cm < 0.02);
  CHECK(angle_deg < 0.1);
}

TEST_CASE("mutant_approach_without_the_arrival_term_turns_down_in_one_step", "[unit]") {
  ExpertOptions no_arrival_term;
  no_arrival_term.arrival_weight = 0.0;
  const auto [lateral_cm, angle_deg] = arrival_jump(no_arrival_term);
  INFO("median last approach step: " << lateral_cm << " cm sideways, " << angle_deg << " deg");
  CHECK_FALSE((lateral_cm < 0.02 && angle_deg < 0.1));
  ExpertOptions negative;
  negative.arrival_weight = -1.0;
  std::mt19937_64 rng(1);
  CHECK_THROWS_AS(
      plan_in_hole_frame(RigidTransform::planar(0.0, 0.0, 15.0), rng, CollisionChecker(), negative),
      InvalidArgument);
}
