// Closed-loop rollouts on the 3D task: the closed-loop expert inserts the blade on train, ood and
// random-se3 scenes, and its rollout of g * scene is g times its rollout of the scene (a policy
// that moves along world axes is the planted fault).
#include <catch2/catch.hpp>

#include "handcentric/core/errors.hpp"
#include "handcentric/props/catch.hpp"
#include "handcentric/props/observation/generators.hpp"
#include "handcentric/sim/insert3d/expert.hpp"
#include "handcentric/sim/insert3d/rollout.hpp"
#include "worst_error.hpp"  // tests/support

using namespace handcentric;
using namespace handcentric::sim::insert3d;
using handcentric::sim::Outcome;

namespace {

// A planted fault: moves straight down the WORLD's z axis, 0.49 cm a step, whatever the slot.
class WorldDown final : public ChunkPolicy {
 public:
  std::string name() const override { return "world-down"; }
  std::vector<RigidTransform> act(const Scene& observation, std::uint64_t) const override {
    std::vector<RigidTransform> chunk;
    for (int k = 1; k <= 16; ++k) {
      chunk.push_back(RigidTransform::from_translation(Eigen::Vector3d(0.0, 0.0, -0.49 * k)) *
                      observation.world_T_hand0());
    }
    return chunk;
  }
};

// A policy that commands a 10 cm jump along the hand's -z every time.
class Jump final : public ChunkPolicy {
 public:
  std::string name() const override { return "jump"; }
  std::vector<RigidTransform> act(const Scene& observation, std::uint64_t) const override {
    return {observation.world_T_hand0() *
            RigidTransform::from_translation(Eigen::Vector3d(0.0, 0.0, -10.0))};
  }
};

/// Claim: rollout(g * scene) = g * rollout(scene), pose by pose within 1e-9, same outcome.
auto rollouts_are_equivariant(std::shared_ptr<const ChunkPolicy> policy) {
  return [policy] {
    const CollisionChecker checker;
    const auto index = *rc::gen::inRange<std::uint64_t>(0, 1000000);
    const TaskScene scene = sample_scene(SceneDistribution::train(), 3, index);
    const RigidTransform g = *props::group_element(props::Group::se3);
    const Rollout original = rollout(*policy, scene, 5, checker);
    const Rollout moved = rollout(*policy, g * scene, 5, checker);
    RC_ASSERT(original.outcome == moved.outcome);
    RC_ASSERT(original.world_T_hand.size() == moved.world_T_hand.size());
    double worst = 0.0;
    for (std::size_t t = 0; t < original.world_T_hand.size(); ++t) {
      worst = test::worst_of(worst, distance(moved.world_T_hand[t], g * original.world_T_hand[t]));
    }
    RC_ASSERT(worst <= 1e-9);
  };
}

props::PropertyParams rollout_params() {
  props::PropertyParams params = props::property_params();
  params.cases = std::min(params.cases, 100);  // each case runs two closed-loop rollouts
  return params;
}

}  // namespace

TEST_CASE("insert3d_closed_loop_expert_inserts_on_train_ood_and_random_se3_scenes", "[unit]") {
  const CollisionChecker checker;
  const ClosedLoopExpert expert;
  for (const SceneDistribution& distribution :
       {SceneDistribution::train(), SceneDistribution::ood(), SceneDistribution::random_se3()}) {
    int successes = 0;
    for (const TaskScene& scene : sample_scenes(distribution, 30, 2)) {
      const Rollout result = rollout(expert, scene, 1, checker);
      successes += result.outcome == Outcome::success;
      CHECK(result.clipped == 0);
    }
    INFO(distribution.name());
    CHECK(successes == 30);
  }
}

TEST_CASE("insert3d_closed_loop_rollouts_are_se3_equivariant", "[property]") {
  const auto outcome = props::run_property(
      "rollout(g * scene) = g * rollout(scene)",
      rollouts_are_equivariant(std::make_shared<ClosedLoopExpert>()), rollout_params());
  INFO(outcome.message);
  REQUIRE(outcome.passed);
}

TEST_CASE("mutant_insert3d_a_policy_moving_along_world_axes_is_not_equivariant", "[property]") {
  const auto outcome = props::run_property("world-down rollouts under se3",
                                           rollouts_are_equivariant(std::make_shared<WorldDown>()),
                                           rollout_params(), props::Expect::failure);
  CHECK_FALSE(outcome.passed);
}

TEST_CASE("insert3d_the_slot_is_read_back_from_the_four_corners", "[unit]") {
  const TaskScene scene = sample_scene(SceneDistribution::random_se3(), 1, 7);
  const Scene observation = observe(scene, {scene.world_T_hand_start}, 2);
  REQUIRE(observation.world_T_hand_history.size() == 3u);
  const RigidTransform hand_T_slot = hand_T_slot_from_corners(observation.hand_points);
  CHECK(distance(scene.world_T_hand_start * hand_T_slot, scene.world_T_slot) < 1e-12);
  CHECK_THROWS_AS(hand_T_slot_from_corners({Eigen::Vector3d::Zero()}), InvalidScene);
}

TEST_CASE("insert3d_commands_beyond_the_step_limits_are_clipped_and_counted", "[unit]") {
  const CollisionChecker checker;
  const TaskScene scene{RigidTransform(),
                        RigidTransform::from_translation(Eigen::Vector3d(0.0, 0.0, 20.0))};
  RolloutOptions options;
  options.max_replans = 3;
  const Rollout result = rollout(Jump(), scene, 1, checker, options);
  CHECK(result.clipped == 3);
  REQUIRE(result.world_T_hand.size() == 4u);
  CHECK(std::abs(result.world_T_hand[1].translation().z() - (20.0 - kMaxStepCm)) < 1e-12);
  CHECK(result.outcome == Outcome::timeout);
  options.execute = 0;
  CHECK_THROWS_WITH(rollout(Jump(), scene, 1, checker, options),
                    Catch::Matchers::Contains("got 0"));
}
