#pragma once
// A policy's named outputs and hands, as the Python module's outputs= / hands= and a policy
// plug-in's hello declare them (docs/AUDIT_YOUR_POLICY.md, "Your policy as it is"). Each entry is
// audited as a map of its own, with the same observations, noise and seeds:
//   pose       a chunk of world-frame poses, which must move with g: a(g o) = g a(o);
//   invariant  numbers of any shape per observation (a gripper width per step, a terminate
//              flag), which must not change: u(g o) = u(o).
// An invariant entry u is handed to the checks as the poses T_0 [I, u_3j..3j+2] (its numbers
// three at a time as positions in the hand's frame at T_0, the last padded with zeros): g moves
// T_0 to g T_0, so these poses move with g exactly when u is invariant, and a change of u by d
// moves them by d. Every check then decides invariance as it decides equivariance, in every mode,
// with the output's own units as its errors.
//
// Several hands (hands = ("left", "right")): the first hand's history is the scene's own, T_0,
// T_-1, ...; each other hand h is one more world-frame pose of the scene, the extra pose
// "hand:h", its pose now S_0, and its history follows the first hand's motion,
// S_k = S_0 T_0^-1 T_k. A global g moves S_0 to g S_0 and so S_k to g S_k: every hand's history
// moves with g, and a policy that reads a hand's world position is seen under translation, the
// witness naming "hand:h". Each hand is a pose output, named after it.
#include <optional>
#include <string>
#include <vector>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/scene.hpp"

namespace handcentric::props {

enum class OutputKind { pose, invariant };

struct NamedOutput {
  std::string name;
  OutputKind kind = OutputKind::pose;
};

/// "pose" or "invariant".
std::string to_string(OutputKind kind);
/// The kind named `text` ("pose", "invariant"); nullopt for anything else.
std::optional<OutputKind> parse_output_kind(const std::string& text);

/// The poses T_0 [I, u_3j..3j+2] of an invariant entry's `count` numbers u (see the top).
std::vector<RigidTransform> invariant_as_poses(const double* u, std::size_t count,
                                               const RigidTransform& T0);

/// The prefix of the extra poses that carry the other hands' poses now ("hand:right").
inline constexpr const char* kHandPosePrefix = "hand:";

/// The outputs of a policy with `hands`: each hand a pose output, first, then the `declared`
/// ones that name no hand. InvalidArgument naming `keyword` (the caller's spelling of outputs=)
/// for a hand declared other than a pose.
std::vector<NamedOutput> outputs_with_hands(const std::vector<std::string>& hands,
                                            const std::vector<NamedOutput>& declared,
                                            const std::string& keyword);

/// Hand `hand`'s history in `scene`: S_k = S_0 T_0^-1 T_k, S_0 the scene's extra pose
/// "hand:<hand>". InvalidArgument when the scene has no such pose.
std::vector<RigidTransform> other_hand_history(const Scene& scene, const std::string& hand);

}  // namespace handcentric::props
