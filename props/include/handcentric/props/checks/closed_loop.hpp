#pragma once
// The closed-loop audit of a policy that keeps state between calls (an action queue, temporal
// ensembling, an observation buffer): is the executed trajectory of g o_1..g o_T the g-image of
// that of o_1..o_T?
//
// An episode: a scene drawn as the checks draw theirs (its hand history, and its points as
// objects fixed in the world: the world points, and the eye-in-hand points placed in the world at
// T_0), and a g of the group. Two rollouts of T steps each, each started afresh
// (ClosedLoopOptions::start_episode, e.g. the policy's reset): one from the scene, one from g
// times it. At each step the policy is asked once (past any cache: its state is the point) with
// the step's noise, the same on both sides; the first pose of what it returns is executed: the
// hand moves there, the history takes it as T_0, and the eye-in-hand points are the objects seen
// from the new hand frame (the world points, in the third-person view, stay as they are). The
// chunks returned are compared step by step and whole (the pose executed and every other, as the
// pointwise checks compare a chunk), B_t against g A_t, pose by pose by |R_a - R_b|_F +
// |p_a - p_b|, within REL (1 + L) with L the largest translation of either rollout and its
// scene; chunks of different lengths differ; a larger
// difference that is at most 8 times the rollout's own response to a rounding-level
// perturbation of its scene (and that response rounding-sized) is rounding, as in check.hpp.
// Recorded observations with an episode index (options.shape.recorded) are replayed instead, as
// recorded_episodes.hpp says; without an index, the episodes start from recorded observations.
// A "yes" says so for the episodes run: a breaking that needs more steps, or a state the
// episodes never reach, is not seen (the verdict's cases are its episodes).
#include <functional>

#include "handcentric/props/checks/check.hpp"
#include "handcentric/props/noisy_policy.hpp"
#include "handcentric/props/verdict.hpp"

namespace handcentric::props {

struct ClosedLoopOptions {
  int episodes = 20;  ///< 1 to kMaxCases (recorded: 1 to the number recorded)
  int steps = 16;     ///< the episode's length T, 1 to 10000 (recorded: not read)
  /// Called before each rollout (the policy's reset); may be empty.
  std::function<void()> start_episode;
  /// The poses of each returned chunk before this index are executed, not compared: 1 when the
  /// policy hands the loop the pose it executes (one of its outputs) ahead of another output's
  /// chunk, which is the one compared.
  std::size_t compared_from = 0;
};

/// The closed-loop verdict of `policy` under `group` (mode closed_loop, component policy): its
/// cases are the episodes with g far from the identity; a failure's witness is the episode's
/// scene and g, before/after the poses of g A_t and B_t that differ most, flattened as [p, r(R)],
/// at the first step that differs, its detail naming the episode, the step and the pose.
/// InvalidArgument for episodes or steps out of range.
Verdict check_policy_closed_loop(const NoisyPolicy& policy, Group group,
                                 const CheckOptions& options, const ClosedLoopOptions& loop);

}  // namespace handcentric::props
