// Theorem 1 in closed loop: a TRAINED hand-centric policy, rolled out on a scene and on a global
// transform of it with the same seed, drives the hand along the transformed trajectory to the
// same outcome. This is why Table 1's OOD column can match its 100-demo column. The same loop
// with absolute actions is the planted fault: its trajectories are not transformed.
#include <catch2/catch.hpp>
#include <numbers>

#include "handcentric/policy/trainer.hpp"
#include "handcentric/sim/collision.hpp"
#include "handcentric/sim/demos.hpp"
#include "handcentric/sim/expert.hpp"
#include "handcentric/sim/rollout.hpp"
#include "handcentric/sim/scenes.hpp"
#include "worst_error.hpp"  // tests/support

using namespace handcentric;

namespace {

// A small policy trained on 8 expert demos of train scenes (seconds, not minutes).
policy::LearnedPolicy trained_policy(const std::string& representation) {
  const sim::CollisionChecker checker;
  const auto scenes = sim::sample_scenes(sim::SceneDistribution::train(), 8, 11);
  const sim::ExpertRun run = sim::expert_demos(scenes, 11, checker);
  policy::PolicyConfig config;
  config.representation = representation;
  config.hidden_width = 64;
  config.hidden_layers = 2;
  config.steps = 300;
  config.batch_size = 64;
  config.history_length = 2;  // what sim::rollout observes by default (RolloutOptions::history)
  return policy::train_policy(
      config, sim::training_scenes(run.demos, config.history_length, config.chunk_length), 5);
}

// Largest |g T_t - T'_t| over the two rollouts' common steps (cm + Frobenius of the rotation).
double trajectory_gap(const sim::Rollout& original, const sim::Rollout& moved,
                      const RigidTransform& g) {
  double worst = 0.0;
  const std::size_t n = std::min(original.world_T_hand.size(), moved.world_T_hand.size());
  for (std::size_t t = 0; t < n; ++t) {
    worst = test::worst_of(worst, distance(g * original.world_T_hand[t], moved.world_T_hand[t]));
  }
  return worst;
}

// The worst gap over 4 OOD-like transforms of 4 scenes.
double worst_gap(const ChunkPolicy& policy, bool& same_outcomes) {
  const sim::CollisionChecker checker;
  const auto scenes = sim::sample_scenes(sim::SceneDistribution::train(), 4, 77);
  const RigidTransform g = RigidTransform::planar(std::numbers::pi * 0.9, 23.0, -31.0);
  double worst = 0.0;
  same_outcomes = true;
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const sim::Rollout original = sim::rollout(policy, scenes[i], checker, 3 + i);
    const sim::Rollout moved = sim::rollout(policy, g * scenes[i], checker, 3 + i);
    same_outcomes =
        same_outcomes && original.outcome == moved.outcome && original.steps == moved.steps;
    worst = test::worst_of(worst, trajectory_gap(original, moved, g));
  }
  return worst;
}

}  // namespace

TEST_CASE("a_trained_hand_centric_policy_is_equivariant_in_closed_loop", "[experiment]") {
  bool same_outcomes = false;
  const double gap = worst_gap(trained_policy("hand_centric"), same_outcomes);
  INFO("largest gap between g * rollout(scene) and rollout(g * scene): " << gap);
  // the bound for trained models (policy issue, item 8); measured: ~2e-14
  CHECK(gap < 1e-6);
  CHECK(same_outcomes);
}

TEST_CASE("mutant_absolute_policy_is_not_equivariant_in_closed_loop", "[experiment]") {
  bool same_outcomes = false;
  const double gap = worst_gap(trained_policy("absolute"), same_outcomes);
  INFO("largest gap: " << gap);
  CHECK(gap > 1.0);  // centimetres: the moved rollout goes elsewhere
}
