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
// Outcome: success as soon as the tip is kSuccessDepth deep inside the hole (is_inserted,
// geometry.hpp); collision at the first contact; timeout when the replans run out; invalid when
// the policy returns a non-finite pose or throws NonFiniteAction (core/errors.hpp), which ends
// the rollout there. An invalid trial is a failure with its own count, so one diverging scene in
// a long evaluation is reported rather than fatal; RolloutOptions::stop_on_invalid makes it an
// error instead.
#include <cstdint>
#include <string>
#include <vector>

#include "handcentric/core/chunk_policy.hpp"
#include "handcentric/core/scene.hpp"
#include "handcentric/sim/collision.hpp"
#include "handcentric/sim/expert.hpp"
#include "handcentric/sim/outcome.hpp"
#include "handcentric/sim/scenes.hpp"

namespace handcentric::sim {

/// Control steps a rollout may take (25 replans of 8 executed poses): the time limit of the task.
constexpr int kStepBudget = 200;

struct RolloutOptions {
  int history = 2;       ///< H past poses in the observation
  int execute = 8;       ///< poses executed per chunk
  int max_replans = 25;  ///< kStepBudget / execute
  double max_step_cm = kMaxStepCm;
  double max_step_deg = kMaxStepDeg;
  /// A non-finite pose from the policy: false ends the rollout as Outcome::invalid, true throws
  /// NonFiniteAction naming the policy, the replan and the chunk entry (`eval --strict`).
  bool stop_on_invalid = false;

  /// Throws InvalidArgument naming the field for a non-positive value (history may be 0).
  void validate() const;

  /// Options for a policy that observes `history` past poses and executes `execute` poses per
  /// chunk, with replans enough for kStepBudget steps (the same time limit for every execute).
  static RolloutOptions for_policy(int history, int execute);
};

struct Rollout {
  Outcome outcome = Outcome::timeout;
  int steps = 0;                             ///< control steps executed
  int replans = 0;                           ///< act() calls
  int clipped = 0;                           ///< commands clipped to the step limits
  std::vector<RigidTransform> world_T_hand;  ///< [0] = start, then one pose per step (the last
                                             ///< one is the colliding pose after a collision)
  std::string invalid_reason;                ///< Outcome::invalid: what the policy returned, where
};

/// The observation at the end of `world_T_hand` (history of `history` past poses, eye-in-hand
/// corners of the opening). Throws InvalidArgument for an empty trajectory or history < 0.
Scene observation(const RigidTransform& world_T_hole,
                  const std::vector<RigidTransform>& world_T_hand, int history,
                  const PegHoleGeometry& geometry = PegHoleGeometry());

/// One rollout; act() call r gets the noise seed stream_seed(seed, r). Throws InvalidArgument
/// when the policy returns an empty chunk (naming the policy and the replan); a non-finite pose
/// is Outcome::invalid, or NonFiniteAction with options.stop_on_invalid.
Rollout rollout(const ChunkPolicy& policy, const TaskScene& scene, const CollisionChecker& checker,
                std::uint64_t seed, const RolloutOptions& options = RolloutOptions());

/// Bumped whenever a change of the rollout or of its success test can change an outcome, so that
/// stored outcomes (table1's results/) from an earlier rule are not read as current ones.
/// 2: is_inserted requires the tip inside the hole (before, a tip behind the hole's bottom wall
/// counted).
inline constexpr int kRolloutRulesVersion = 2;

struct RolloutSummary {
  int trials = 0, success = 0, collision = 0, timeout = 0, clipped = 0;
  int invalid = 0;                   ///< trials whose policy returned a non-finite pose
  int first_invalid_scene = -1;      ///< index of the first such scene, -1 when none
  std::string first_invalid_reason;  ///< its Rollout::invalid_reason
};

/// Rollouts on every scene (scene i uses seed stream_seed(seed, i)), counted. With
/// options.stop_on_invalid the first invalid trial throws NonFiniteAction naming its scene.
RolloutSummary evaluate(const ChunkPolicy& policy, const std::vector<TaskScene>& scenes,
                        const CollisionChecker& checker, std::uint64_t seed,
                        const RolloutOptions& options = RolloutOptions());

}  // namespace handcentric::sim
