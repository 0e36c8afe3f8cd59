#pragma once
// Which scenes a check runs on, and which camera renders them: one choice, two names for it.
//   eye_in_hand  : no world points (Theorem 1's assumption); the camera on the hand.
//   third_person : one to eight world-frame points that move with g, beside eye-in-hand points;
//                  the camera fixed in the world.
#include <string>

namespace handcentric::props {

enum class View { eye_in_hand, third_person };

/// "eye_in_hand", "third_person".
std::string to_string(View view);

}  // namespace handcentric::props
