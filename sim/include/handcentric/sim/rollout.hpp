#pragma once
// Closed-loop, chunked rollouts of a ChunkPolicy on a task scene (Sec. 4.2): "rollouts are
// simulated only kinematically ... with a collision checker to assess the success".
//
// Loop: build the observation (history T_0, T_{-1}, T_{-2}, the first pose repeated before the
// start, and the eye-in-hand corners of the opening), call act(), execute the first `execute`
// poses of the chunk, replan; at most `max_replans` calls. The hand moves kinematically to each
// commanded pose, projected onto the plane (theta from the rotation's first column, z dropped);
// a command beyond the per-step limits is clipped to them along the straight (theta, x, y) line,
// and counted. Every motion is checked continuously (collision.hpp) in the hole frame.
// Outcome: success as soon as the tip is kSuccessDepth deep inside the opening; collision at the
// first contact; timeout when the replans run out.
#include <cstdint>
#include <string>
#include <vector>

#include "handcentric/core/chunk_policy.hpp"
#include "handcentric/core/scene.hpp"
#include "handcentric/sim/collision.hpp"
#include "handcentric/sim/expert.hpp"
#include "handcentric/sim/scenes.hpp"

namespace handcentric::sim {

/// Control steps a rollout may take (25 replans of 8 executed poses): the time limit of the task.
constexpr int kStepBudget = 200;

struct RolloutOptions {
  int history = 2;         ///< H past poses in the observation
  int execute = 8;         ///< poses executed per chunk
  int max_replans = 25;    ///< kStepBudget / execute
  double max_step_cm = kMaxStepCm;
  double max_step_deg = kMaxStepDeg;

  /// Throws InvalidArgument naming the field for a non-positive value (history may be 0).
  void validate() const;

  /// Options for a policy that observes `history` past poses and executes `execute` poses per
  /// chunk, with replans enough for kStepBudget steps (the same time limit for every execute).
  static RolloutOptions for_policy(int history, int execute);
};

enum class Outcome { success, collision, timeout };

/// "success", "collision", "timeout".
std::string outcome_name(Outcome outcome);

struct Rollout {
  Outcome outcome = Outcome::timeout;
  int steps = 0;                             ///< control steps executed
  int replans = 0;                           ///< act() calls
  int clipped = 0;                           ///< commands clipped to the step limits
  std::vector<RigidTransform> world_T_hand;  ///< [0] = start, then one pose per step (the last
                                             ///< one is the colliding pose after a collision)
};

/// The observation at the end of `world_T_hand` (history of `history` past poses, eye-in-hand
/// corners of the opening). Throws InvalidArgument for an empty trajectory or history < 0.
Scene observation(const RigidTransform& world_T_hole, const std::vector<RigidTransform>& world_T_hand, int history,
                  const PegHoleGeometry& geometry = PegHoleGeometry());

/// Whether the hand at hole_T_hand has its tip kSuccessDepth deep and inside the opening's width.
bool is_inserted(const RigidTransform& hole_T_hand, const PegHoleGeometry& geometry = PegHoleGeometry());

/// One rollout; act() call r gets the noise seed stream_seed(seed, r). Throws InvalidArgument
/// when the policy returns an empty chunk or a non-finite pose (naming the policy and the replan).
Rollout rollout(const ChunkPolicy& policy, const TaskScene& scene, const CollisionChecker& checker,
                std::uint64_t seed, const RolloutOptions& options = RolloutOptions());

struct RolloutSummary {
  int trials = 0, success = 0, collision = 0, timeout = 0, clipped = 0;
};

/// Rollouts on every scene (scene i uses seed stream_seed(seed, i)), counted.
RolloutSummary evaluate(const ChunkPolicy& policy, const std::vector<TaskScene>& scenes,
                        const CollisionChecker& checker, std::uint64_t seed,
                        const RolloutOptions& options = RolloutOptions());

}  // namespace handcentric::sim
