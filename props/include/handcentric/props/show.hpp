#pragma once
// How RapidCheck prints handcentric values in a counterexample (found by ADL): 17 significant
// digits, so a printed witness reproduces the failing doubles exactly.
#include <ostream>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/rotation.hpp"
#include "handcentric/core/scene.hpp"

namespace handcentric {

void showValue(const Rotation& rotation, std::ostream& os);
void showValue(const RigidTransform& transform, std::ostream& os);
void showValue(const Scene& scene, std::ostream& os);

}  // namespace handcentric
