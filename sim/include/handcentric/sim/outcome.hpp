#pragma once
// How a closed-loop rollout ended, on either task (the 2D peg-in-hole and the 3D insertion).
#include <string>

namespace handcentric::sim {

/// success: the task's goal test held; collision: the held part (peg or blade) touched the fixed
/// one (hole or slot); timeout: the replans ran out; invalid: the policy returned a non-finite
/// pose or threw NonFiniteAction.
enum class Outcome { success, collision, timeout, invalid };

/// "success", "collision", "timeout", "invalid".
std::string outcome_name(Outcome outcome);

}  // namespace handcentric::sim
