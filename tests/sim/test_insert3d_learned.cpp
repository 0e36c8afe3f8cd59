// Theorem 1 in closed loop in 3D: a TRAINED hand-centric flow policy, rolled
// out on a 3D scene and on g * scene for random g in SE(3) with the same noise seeds, drives the
// hand along g times its original trajectory to the same outcome, whatever the network learned.
// The planted fault is the same loop with absolute actions: its trajectories do not move with g.
// The policies see what table2's and `handcentric eval --task insert3d`'s do: the corners and the
// slot points computed from them (experiments/insert3d_key_points.hpp).
#include <catch2/catch.hpp>
#include <random>

#include "handcentric/core/sampling.hpp"
#include "handcentric/experiments/insert3d_key_points.hpp"
#include "handcentric/policy/errors.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/policy/trainer.hpp"
#include "handcentric/sim/insert3d/expert.hpp"
#include "handcentric/sim/insert3d/rollout.hpp"
#include "handcentric/sim/insert3d/scenes.hpp"
#include "worst_error.hpp"  // tests/support

using namespace handcentric;
namespace insert3d = sim::insert3d;

namespace {

constexpr int kHistory = 2;  // past poses: the world-frame proprioception is in the observation

// A small 3D policy trained on 6 expert demos of train scenes for 300 steps (seconds).
policy::LearnedPolicy trained_3d_policy(const std::string& representation) {
  const insert3d::CollisionChecker checker;
  const auto scenes = insert3d::sample_scenes(insert3d::SceneDistribution::train(), 6, 21);
  const insert3d::ExpertRun run = insert3d::expert_demos(scenes, 21, checker);
  policy::PolicyConfig config;
  config.task = policy::kTaskInsert3d;
  config.representation = representation;
  config.hidden_width = 64;
  config.hidden_layers = 2;
  config.steps = 300;
  config.batch_size = 64;
  config.history_length = kHistory;
  const auto samples = insert3d::training_scenes(run.demos, kHistory, config.chunk_length);
  return policy::train_policy(config, experiments::with_slot_key_points(samples), 5);
}

// The largest |g T_t - T'_t| (cm + Frobenius of the rotation) over rollouts of 3 train scenes
// and of g * scene for 3 random g in SE(3) each (rotation Haar-uniform, translation up to 60 cm).
double worst_gap_3d(const ChunkPolicy& policy, bool& same_outcomes) {
  const insert3d::CollisionChecker checker;
  insert3d::RolloutOptions options;
  options.history = kHistory;
  options.execute = 4;
  options.max_replans = 12;  // 48 steps: enough to compare trajectories, quick to run
  const auto scenes = insert3d::sample_scenes(insert3d::SceneDistribution::train(), 3, 77);
  std::mt19937_64 rng(2026);
  double worst = 0.0;
  same_outcomes = true;
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const insert3d::Rollout original =
        insert3d::rollout(policy, scenes[i], 3 + i, checker, options);
    for (int draw = 0; draw < 3; ++draw) {
      const RigidTransform g = random_transform(rng, 60.0);
      const insert3d::Rollout moved =
          insert3d::rollout(policy, g * scenes[i], 3 + i, checker, options);
      same_outcomes = same_outcomes && original.outcome == moved.outcome &&
                      original.world_T_hand.size() == moved.world_T_hand.size();
      const std::size_t n = std::min(original.world_T_hand.size(), moved.world_T_hand.size());
      for (std::size_t t = 0; t < n; ++t) {
        worst =
            test::worst_of(worst, distance(g * original.world_T_hand[t], moved.world_T_hand[t]));
      }
    }
  }
  return worst;
}

}  // namespace

TEST_CASE("a_trained_hand_centric_3d_policy_is_se3_equivariant_in_closed_loop", "[property]") {
  bool same_outcomes = false;
  const experiments::SlotKeyPointPolicy policy(
      std::make_shared<policy::LearnedPolicy>(trained_3d_policy("hand_centric")));
  const double gap = worst_gap_3d(policy, same_outcomes);
  INFO("largest gap between g * rollout(scene) and rollout(g * scene): " << gap);
  CHECK(gap < 1e-9);
  CHECK(same_outcomes);
}

TEST_CASE("mutant_absolute_3d_policy_is_not_se3_equivariant_in_closed_loop", "[property]") {
  bool same_outcomes = false;
  const experiments::SlotKeyPointPolicy policy(
      std::make_shared<policy::LearnedPolicy>(trained_3d_policy("absolute")));
  const double gap = worst_gap_3d(policy, same_outcomes);
  INFO("largest gap: " << gap);
  CHECK(gap > 1.0);  // centimetres: the moved rollout goes elsewhere
}

TEST_CASE("the_slot_key_points_are_the_slot_seen_from_the_hand_and_need_four_corners", "[unit]") {
  const insert3d::BladeSlotGeometry geometry;
  const insert3d::TaskScene scene =
      insert3d::sample_scene(insert3d::SceneDistribution::random_se3(), 4, 0);
  const Scene observation = insert3d::observe(scene, {scene.world_T_hand_start}, 0);
  const Scene input = experiments::with_slot_key_points(observation);
  REQUIRE(input.hand_points.size() == 4u + experiments::kSlotKeyPoints);
  const RigidTransform hand_T_slot = scene.world_T_hand_start.inverse_compose(scene.world_T_slot);
  CHECK((input.hand_points.back() - hand_T_slot * Eigen::Vector3d(0, 0, -insert3d::kSlotDepth))
            .norm() < 1e-9);
  const double outer_x = geometry.inner_half_x() + insert3d::kSlotWallThickness;
  const double outer_y = geometry.inner_half_y() + insert3d::kSlotWallThickness;
  CHECK((input.hand_points[6] - hand_T_slot * Eigen::Vector3d(outer_x, outer_y, 0)).norm() < 1e-9);
  Scene three = observation;
  three.hand_points.pop_back();
  CHECK_THROWS_AS(experiments::with_slot_key_points(three), InvalidScene);
}

TEST_CASE("a_model_records_its_task_and_a_2d_model_on_the_3d_task_is_a_typed_error", "[unit]") {
  policy::PolicyConfig config;
  config.task = policy::kTaskInsert3d;
  CHECK(policy::PolicyConfig::from_text(config.to_text()).task == "insert3d");
  // A 2D config writes no task line, so 2D model files and table1's cell hashes are unchanged,
  // and a file without one (written before the 3D task) reads as peg2d.
  CHECK(policy::PolicyConfig().to_text().find("task=") == std::string::npos);
  CHECK(policy::PolicyConfig::from_text("head=flow\n").task == "peg2d");
  CHECK_THROWS_WITH(policy::PolicyConfig::from_text("task=peg3d\n"),
                    Catch::Contains("'peg3d'") && Catch::Contains("peg2d or insert3d"));
  const policy::LearnedPolicy model = trained_3d_policy("hand_centric");
  CHECK(model.config().hand_points == 4 + experiments::kSlotKeyPoints);
  const policy::LearnedPolicy reloaded =
      policy::deserialize_model(policy::serialize_model(model), "m.hcm");
  CHECK(reloaded.config().task == "insert3d");
  CHECK_NOTHROW(policy::require_task(reloaded, policy::kTaskInsert3d, "m.hcm"));
  CHECK_THROWS_AS(policy::require_task(reloaded, policy::kTaskPeg2d, "m.hcm"), TaskMismatch);
  CHECK_THROWS_WITH(policy::require_task(reloaded, policy::kTaskPeg2d, "m.hcm"),
                    Catch::Contains("m.hcm") && Catch::Contains("'insert3d'") &&
                        Catch::Contains("'peg2d'") && Catch::Contains("--task insert3d"));
}
