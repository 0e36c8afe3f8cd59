#pragma once
// Planted faults for continuous motion checks, shared by the 2D and 3D collision tests: each
// must miss a motion through a wall that the real checker catches.
#include "handcentric/core/rigid_transform.hpp"

namespace handcentric::testing {

/// Checks the two end poses only.
template <typename Checker>
bool endpoints_only(const Checker& checker, const RigidTransform& a, const RigidTransform& b) {
  return checker.collides(a) || checker.collides(b);
}

/// A fixed subdivision into 4 pieces, whatever the motion's length.
template <typename Checker,
          RigidTransform (*Interpolate)(const RigidTransform&, const RigidTransform&, double)>
bool four_samples(const Checker& checker, const RigidTransform& a, const RigidTransform& b) {
  for (int i = 0; i <= 4; ++i) {
    if (checker.collides(Interpolate(a, b, i / 4.0))) return true;
  }
  return false;
}

}  // namespace handcentric::testing
