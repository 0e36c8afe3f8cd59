#pragma once
// One closed-loop episode judged: the chunks of the rollout from o_1..o_T (a) and of the one from
// g o_1..g o_T (b) compared step by step, B_t against g A_t, as closed_loop.hpp says; shared by
// the generated episodes (closed_loop.cpp) and the recorded ones (recorded_episodes.cpp).
#include <functional>
#include <string>
#include <vector>

#include "handcentric/props/checks/check.hpp"
#include "handcentric/props/verdict.hpp"

namespace handcentric::props {

/// What a policy returned at each step of one rollout.
using RolloutChunks = std::vector<std::vector<RigidTransform>>;

struct ClosedLoopEpisode {
  const Scene* start = nullptr;  ///< o_1: the witness's scene, and the near-identity test of g
  RigidTransform g;
  RolloutChunks a, b;         ///< the rollouts from o and from g o, of the same number of steps
  double length_scale = 1.0;  ///< L: the largest translation of either rollout and its scenes
  /// The rollout again from a rounding-level perturbation of o (asked only above the floor).
  std::function<RolloutChunks()> nudged;
  /// "closed loop, episode 3 of 20": the witness's detail starts so.
  std::string name;
};

/// The verdict's header for a closed-loop check (component policy, mode closed_loop).
Verdict closed_loop_verdict(Group group, const CheckOptions& options);

/// Counts the episode in `verdict` (a case, or a near-identity case) and returns true when it
/// holds; else sets the verdict to NO with its witness (the first step the rollouts part, the
/// poses that differ most) and returns false. `compared_from` as ClosedLoopOptions says.
bool judge_closed_loop_episode(Verdict& verdict, const ClosedLoopEpisode& episode,
                               const CheckOptions& options, std::size_t compared_from);

/// The noise of each of `steps` steps of episode `episode`: the same on both rollouts, a
/// different seed per episode and step.
std::vector<Eigen::VectorXd> closed_loop_noises(Eigen::Index dimension, const CheckOptions& options,
                                                int episode, int steps);

/// L of one rollout: the largest length_scale of its scenes and translation of its chunks.
double rollout_scale(const std::vector<const Scene*>& scenes, const RolloutChunks& chunks);

}  // namespace handcentric::props
