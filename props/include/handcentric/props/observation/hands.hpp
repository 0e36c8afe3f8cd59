#pragma once
// Several hands in one scene. The scene's own history (world_T_hand_history) is the first hand's:
// its hand points are seen from it. Each other hand h is a set of world-frame extra poses, which
// move with g as every pose of a scene does: "hand:h" its pose now, S_0, and, when its history is
// recorded, "hand:h@-k" its pose k steps ago, S_-k. A drawn scene carries "hand:h" alone (the
// other hand's history then follows the first hand's motion, named_output.hpp).
//
// Recorded observations with history = {hand: (H+1, 4, 4)} are read with every hand as such
// extra poses (and the first hand in sorted order as the scene's history);
// recorded_with_hands() then makes the audit's first hand the scene's own.
#include <string>
#include <vector>

#include "handcentric/core/scene.hpp"
#include "handcentric/props/named_output.hpp"  // kHandPosePrefix, other_hand_history
#include "handcentric/props/observation/recorded.hpp"

namespace handcentric::props {

/// "hand:right" (steps_ago 0) or "hand:right@-2".
std::string hand_pose_name(const std::string& hand, int steps_ago);

/// Whether an extra pose's name is one of a hand's ("hand:...").
bool is_hand_pose(const std::string& name);

/// The poses of `hand` that `scene` carries, S_0, S_-1, ... (a drawn scene's hand: S_0 alone; a
/// hand it does not carry: none).
std::vector<RigidTransform> recorded_hand_history(const Scene& scene, const std::string& hand);

/// The observations as an audit of `hands` (at least two names) sees them: the first hand's
/// recorded history as each scene's own, the others as their extra poses. Throws InvalidArgument
/// naming the hands recorded and those asked for when they are not the same set, and when the
/// data record one history (history = {hand: array} is needed).
RecordedObservations recorded_with_hands(const RecordedObservations& data,
                                         const std::vector<std::string>& hands);

}  // namespace handcentric::props
