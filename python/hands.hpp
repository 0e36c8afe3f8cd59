#pragma once
// Several hands (hands=("left", "right")): the policy is given history={hand: (H+1, 4, 4)} and
// returns one chunk per hand in its dict of outputs, each audited as a "pose" output (verdicts
// per hand).
//
// The first hand's history is the audit's drawn one, T_0, T_-1, ... Each other hand h is drawn
// as one more world-frame pose of the scene, the extra pose "hand:h", its pose now S_0; its
// history follows the first hand's motion, S_k = S_0 T_0^-1 T_k. A global g moves S_0 to g S_0
// and so S_k to g S_k: every hand's history moves with g, as a scene's poses must, and a policy
// that reads a hand's world position is seen under translation, the witness naming "hand:h".
//
// With observations=, each hand's history is recorded (history={hand: (H+1, 4, 4)} in the data):
// the first hand's is the scene's, each other hand's the extra poses "hand:h" (now) and
// "hand:h@-k" (k steps ago), all moving with g, handed to the policy as recorded.
#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "handcentric/props/observation/hands.hpp"
#include "options.hpp"

namespace handcentric::python {

/// The prefix of the extra poses that carry the other hands' poses ("hand:right").
inline constexpr const char* kHandPosePrefix = props::kHandPosePrefix;

/// hands= checked: None or a sequence of at least two distinct names (a string alone is refused:
/// hands=("left", "right")). Sets o.call.hands and adds "hand:h" to the drawn extra poses of c
/// for each hand after the first, or with observations= makes the first hand's recorded history
/// the scenes' (props::recorded_with_hands: the recorded hands must be those named); outputs=
/// then gets each hand as a "pose" output (an output named after a hand must be a pose), before
/// the others.
void set_hands(CommonOptions& o, props::ClassifierOptions& c, py::handle hands);

/// The history argument of a policy call for `rows`: the array of history_in without hands;
/// with hands a dict {hand: array}, each in options.state_format.
py::object history_argument(const std::vector<const Scene*>& rows, const CallOptions& options);

}  // namespace handcentric::python
