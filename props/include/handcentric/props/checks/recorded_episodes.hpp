#pragma once
// The closed loop on the user's recorded episodes (RecordedObservations with an episode index):
// each episode replayed as recorded, o_1..o_T, by a fresh policy (ClosedLoopOptions::
// start_episode), and g o_1..g o_T by another fresh one, with one g of the group per episode and
// the same noise per step on both sides (the generated episodes' seeds, closed_loop.hpp); what it
// returns is compared step by step as the generated closed loop compares it.
//
// A replay is not a rollout: the hand does not move to the pose the policy executes; step t shows
// the policy the t-th recorded observation whatever it did at step t-1. The verdict is about the
// policy's state over the recorded observations (an action queue, an ensembler, an observation
// buffer fed the data), not about the trajectory it would execute; its note says so.
#include "handcentric/props/checks/check.hpp"
#include "handcentric/props/checks/closed_loop.hpp"
#include "handcentric/props/noisy_policy.hpp"
#include "handcentric/props/verdict.hpp"

namespace handcentric::props {

/// The closed-loop verdict (mode closed_loop) of `policy` under `group` on the first
/// `loop.episodes` recorded episodes of options.shape.recorded, in their order (loop.steps is not
/// read: each episode is as long as recorded). In the eye-in-hand view (a shape without world
/// points) the recorded world points are dropped, as the single-call checks drop them. Its cases
/// are the episodes with g far from the identity; a failure's witness is the episode's first
/// observation and g, its detail naming the episode as recorded, its observations, the step and
/// the pose. InvalidArgument, naming the value and the fix: no recorded episodes; episodes above
/// the number recorded; an episode with fewer observations than the poses of its history (H+1):
/// the policy's own history buffer would reach before the episode began.
Verdict check_policy_recorded_episodes(const NoisyPolicy& policy, Group group,
                                       const CheckOptions& options, const ClosedLoopOptions& loop);

}  // namespace handcentric::props
