#include "handcentric/sim/expert_check.hpp"

#include <string>

#include "handcentric/core/errors.hpp"
#include "handcentric/sim/collision.hpp"
#include "handcentric/sim/expert.hpp"
#include "handcentric/sim/policies.hpp"
#include "handcentric/sim/rollout.hpp"

namespace handcentric::sim {

ExpertCheck check_expert(const SceneDistribution& distribution, int scenes, int rollouts,
                         std::uint64_t seed) {
  if (scenes < 1 || rollouts < 1) {
    throw InvalidArgument("check_expert needs at least 1 scene and 1 rollout, got " +
                          std::to_string(scenes) + " and " + std::to_string(rollouts));
  }
  const CollisionChecker checker;
  const ExpertRun run = expert_demos(sample_scenes(distribution, scenes, seed), seed, checker);
  const RolloutSummary summary =
      evaluate(ExpertPolicy(), sample_scenes(distribution, rollouts, seed), checker, seed);
  ExpertCheck check;
  check.solved_rate = run.solved_rate();
  check.discard_rate = run.discard_rate();
  check.rollout_success = summary.success;
  check.rollouts = summary.trials;
  return check;
}

}  // namespace handcentric::sim
