// Closed-loop chunked rollouts with the expert, replayed demos and scripted policies.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "handcentric/core/errors.hpp"
#include "handcentric//core/sampling.hpp"
#include "handcentric/sim/policies.hpp"
#include "handcentric/sim/rollout.hpp"
#include "worst_error.hpp"  // tests/support

using namespace handcentric;
using namespace handcentric::sim;

namespace {

TaskScene scene_at(double theta, double x, double y) {
  const RigidTransform world_T_hole = RigidTransform::planar(0.6, 12.0, -7.0);
  return TaskScene{world_T_hole, world_T_hole * RigidTransform::planar(theta, x, y)};
}

/// Commands one fixed world pose: far away, so every step is clipped.
class JumpPolicy final : public ChunkPolicy {
 public:
  explicit JumpPolicy(RigidTransform target) : target_(target) {}
  std::string name() const override { return "jump"; }
  std::vector<RigidTransform> act(const Scene&, std::uint64_t) const override {
    return {16, target_};
  }

 private:
  RigidTransform target_;
};

/// Returns whatever it was built with (an empty chunk, a NaN pose).
class BrokenPolicy final : public ChunkPolicy {
 public:
  explicit BrokenPolicy(std::vector<RigidTransform> chunk) : chunk_(std::move(chunk)) {}
  std::string name() const override { return "broken"; }
  std::vector<RigidTransform> act(const Scene&, std::uint64_t) const override { return chunk_; }

 private:
  std::vector<RigidTransform> chunk_;
};

/// A planted fault for the equivariance check: moves down in WORLD -y, whatever the hand.
class WorldDownPolicy final : public ChunkPolicy {
 public:
  std::string name() const override { return "world_down"; }
  std::vector<RigidTransform> act(const Scene& o, std::uint64_t) const override {
    std::vector<RigidTransform> chunk;
    for (int k = 1; k <= kChunkLength; ++k)
      chunk.push_back(RigidTransform::planar(0, 0, -0.5 * k) * o.world_T_hand0());
    return chunk;
  }
};

/// Claim (eq. 4): act(g * o, s) = g * act(o, s) for random planar g; the largest error.
double policy_equivariance_error(const ChunkPolicy& policy, int n) {
  std::mt19937_64 rng(33);
  double worst = 0.0;
  const auto scenes = sample_scenes(SceneDistribution::train(), n, 8);
  for (int i = 0; i < n; ++i) {
    const TaskScene& scene = scenes[static_cast<std::size_t>(i)];
    const Scene o = observation(scene.world_T_hole, {scene.world_T_hand_start}, 2);
    const RigidTransform g =
        RigidTransform::planar(2.0 * std::numbers::pi * uniform01(rng),
                               100.0 * uniform01(rng) - 50.0, 100.0 * uniform01(rng) - 50.0);
    const auto chunk = policy.act(o, 5);
    const auto moved = policy.act(g * o, 5);
    if (chunk.size() != moved.size()) return INFINITY;
    for (std::size_t k = 0; k < chunk.size(); ++k)
      worst = test::worst_of(worst, distance(moved[k], g * chunk[k]));
  }
  return worst;
}

}  // namespace

TEST_CASE("the_closed_loop_expert_succeeds_on_train_and_ood_scenes", "[experiment]") {
  const CollisionChecker checker;
  const ExpertPolicy expert;
  for (const auto& distribution : {SceneDistribution::train(), SceneDistribution::ood()}) {
    const RolloutSummary summary = evaluate(expert, sample_scenes(distribution, 40, 3), checker, 3);
    INFO(distribution.name << ": " << summary.success << " successes, " << summary.collision
                           << " collisions, " << summary.timeout << " timeouts");
    CHECK(summary.success >= 0.99 * summary.trials);
    CHECK(summary.clipped == 0);
  }
}

TEST_CASE("demos_replayed_through_the_rollout_loop_succeed", "[property]") {
  const CollisionChecker checker;
  const auto scenes = sample_scenes(SceneDistribution::parse("-180:180"), 40, 4);
  const ExpertRun run = expert_demos(scenes, 4, checker);
  REQUIRE(run.demos.size() == scenes.size());
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const Rollout r = rollout(ReplayPolicy(run.demos[i]), scenes[i], checker, 1);
    INFO("scene " << i << ": " << outcome_name(r.outcome));
    CHECK(r.outcome == Outcome::success);
    CHECK(r.clipped == 0);
    CHECK(r.steps < static_cast<int>(run.demos[i].world_T_hand.size()));
    CHECK(r.replans == (r.steps + 7) / 8);
  }
}

TEST_CASE("scripted_policies_give_each_outcome", "[unit]") {
  const CollisionChecker checker;
  // straight down the axis from above: success
  const Rollout down = rollout(StraightPolicy(), scene_at(0.0, 0.0, 15.1), checker, 1);
  CHECK(down.outcome == Outcome::success);
  CHECK(down.steps == static_cast<int>(std::ceil((15.1 - 8.0 + 5.0) / 0.5)));
  // off the axis by 3 cm: lands on the wall
  CHECK(rollout(StraightPolicy(), scene_at(0.0, 3.0, 15.0), checker, 1).outcome ==
        Outcome::collision);
  // tilted by 2 degrees: the gap closes inside the hole
  CHECK(rollout(StraightPolicy(), scene_at(2.0 * std::numbers::pi / 180.0, 0.0, 15.0), checker, 1)
            .outcome == Outcome::collision);
  // holding still: timeout after 25 replans of 8 steps
  const Rollout hold = rollout(HoldPolicy(), scene_at(0.0, 0.0, 15.0), checker, 1);
  CHECK(hold.outcome == Outcome::timeout);
  CHECK(hold.replans == 25);
  CHECK(hold.steps == 200);
  CHECK(hold.world_T_hand.size() == 201u);
  // a start inside a wall: collision at step 0
  const Rollout stuck = rollout(HoldPolicy(), scene_at(0.0, 2.0, 4.0), checker, 1);
  CHECK(stuck.outcome == Outcome::collision);
  CHECK(stuck.steps == 0);
}

TEST_CASE("commands_beyond_the_step_limits_are_clipped_and_counted", "[unit]") {
  const CollisionChecker checker;
  const TaskScene scene = scene_at(0.0, 0.0, 15.0);
  const RigidTransform far = scene.world_T_hole * RigidTransform::planar(1.0, 0.0, 150.0);
  const Rollout r = rollout(JumpPolicy(far), scene, checker, 1);
  CHECK(r.clipped == r.steps);
  CHECK(r.steps == 200);
  for (std::size_t t = 0; t + 1 < r.world_T_hand.size(); ++t) {
    const RigidTransform step = r.world_T_hand[t].inverse_compose(r.world_T_hand[t + 1]);
    CHECK(step.translation().norm() <= kMaxStepCm * (1.0 + 1e-6));
    CHECK(step.rotation().angle() <= kMaxStepDeg * std::numbers::pi / 180.0 * (1.0 + 1e-6));
  }
}

TEST_CASE("a_policy_returning_garbage_is_a_typed_error_naming_it", "[unit]") {
  const CollisionChecker checker;
  const TaskScene scene = scene_at(0.0, 0.0, 15.0);
  CHECK_THROWS_WITH(
      rollout(BrokenPolicy({}), scene, checker, 1),
      Catch::Matchers::Contains("broken") && Catch::Matchers::Contains("empty chunk"));
  // a non-finite pose ends the rollout as invalid, or is an error with stop_on_invalid
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const RigidTransform bad =
      RigidTransform::unchecked(Eigen::Matrix3d::Identity(), Eigen::Vector3d(nan, 0, 0));
  const Rollout r = rollout(BrokenPolicy({bad}), scene, checker, 1);
  CHECK(r.outcome == Outcome::invalid);
  CHECK(outcome_name(r.outcome) == "invalid");
  CHECK_THAT(r.invalid_reason, Catch::Matchers::Contains("broken") &&
                                   Catch::Matchers::Contains("non-finite") &&
                                   Catch::Matchers::Contains("replan 0"));
  RolloutOptions strict;
  strict.stop_on_invalid = true;
  CHECK_THROWS_AS(rollout(BrokenPolicy({bad}), scene, checker, 1, strict), NonFiniteAction);
  CHECK_THROWS_WITH(rollout(BrokenPolicy({bad}), scene, checker, 1, strict),
                    Catch::Matchers::Contains("non-finite"));
  RolloutOptions options;
  options.execute = 0;
  CHECK_THROWS_AS(rollout(HoldPolicy(), scene, checker, 1, options), InvalidArgument);
}

TEST_CASE("the_observation_holds_h_past_poses_and_the_opening_corners", "[unit]") {
  const TaskScene scene = scene_at(0.3, 1.0, 14.0);
  const Scene o = observation(scene.world_T_hole, {scene.world_T_hand_start}, 2);
  REQUIRE(o.world_T_hand_history.size() == 3u);
  for (const auto& T : o.world_T_hand_history)
    CHECK(T.matrix() == scene.world_T_hand_start.matrix());
  CHECK(o.world_T_hand_chunk.empty());
  const RigidTransform hand_T_hole = hand_T_hole_from_observation(o);
  CHECK(distance(scene.world_T_hand_start * hand_T_hole, scene.world_T_hole) < 1e-12);
  Scene three = o;
  three.hand_points.push_back(Eigen::Vector3d::Zero());
  CHECK_THROWS_AS(hand_T_hole_from_observation(three), InvalidScene);
}

TEST_CASE("the_expert_policy_is_equivariant", "[property]") {
  CHECK(policy_equivariance_error(ExpertPolicy(), 30) < 1e-9);
  CHECK(policy_equivariance_error(StraightPolicy(), 30) < 1e-9);
}

TEST_CASE("mutant_policy_moving_in_world_axes_is_caught", "[property]") {
  CHECK(policy_equivariance_error(WorldDownPolicy(), 30) > 1e-3);
}

TEST_CASE("the_same_seed_gives_the_same_rollout_bit_for_bit", "[unit]") {
  const CollisionChecker checker;
  const TaskScene scene = sample_scene(SceneDistribution::ood(), 2, 0);
  const Rollout a = rollout(ExpertPolicy(), scene, checker, 5);
  const Rollout b = rollout(ExpertPolicy(), scene, checker, 5);
  REQUIRE(a.world_T_hand.size() == b.world_T_hand.size());
  for (std::size_t t = 0; t < a.world_T_hand.size(); ++t)
    CHECK(a.world_T_hand[t].matrix() == b.world_T_hand[t].matrix());
  CHECK_THROWS_WITH(make_scripted_policy("oracle"),
                    Catch::Matchers::Contains("oracle") && Catch::Matchers::Contains("expert"));
}
