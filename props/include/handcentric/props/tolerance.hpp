#pragma once
// Tolerances of the pointwise checks, and the near-identity rule (docs/AUDIT.md).
//
// Rounding grows with the size of the numbers involved, so a pointwise check compares
//   error = |f(g * s) - f(s)|_inf   against   tolerance = kRelativeTolerance * (1 + L)
// with L = the scene's length scale: the largest translation of any pose or point of s and of
// g * s (in metres). 1e-9 is ~1e7 double epsilons: far above the rounding of the few products
// a representation takes (~1e-13 at L = 1e3), far below any real symmetry breaking we know of.
//
// Near identity: a transform g with rotation angle + |p~| / (1 + L) below kNearIdentity moves
// nothing measurably, so a case with such a g cannot show a symmetry. Such cases are still run
// and must still pass (they catch NaNs and blow-ups at the identity), but they are not counted
// in a verdict's cases, and a check holds only with at least one far case.
#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/scene.hpp"

namespace handcentric::props {

constexpr double kRelativeTolerance = 1e-9;

// float32 rounding (`--precision float32`): 1e-4 is about 1700 units of float32 rounding
// (2^-24 = 6e-8). A pose pipeline in float32 rounds its inputs and each of a few dozen products
// at the scene's length scale (~1e-7 (1 + L) each); a rotation vector taken through acos near pi
// loses up to sqrt(2^-24) = 2.4e-4 in the angle, which 1e-4 (1 + L) covers for L >= 1.4 m (the
// audit's scenes start up to 17 m out). Real symmetry breaking in the audit's scenes is
// O(0.01) and above, far over it.
constexpr double kFloat32RelativeTolerance = 1e-4;
constexpr double kNearIdentity = 1e-6;

/// L: the largest translation norm of any pose or point of the scene (0 for an empty scene).
double length_scale(const Scene& scene);

/// relative * (1 + max(L(s), L(g * s))); relative = kRelativeTolerance unless a check's
/// options say otherwise (e.g. 1e-4 for a network computed in float).
double pointwise_tolerance(const Scene& scene, const Scene& moved,
                           double relative = kRelativeTolerance);

/// angle(R~) + |p~| / (1 + L(s)): how far g is from the identity, relative to the scene.
double distance_from_identity(const RigidTransform& g, const Scene& scene);

/// distance_from_identity(g, scene) < kNearIdentity.
bool near_identity(const RigidTransform& g, const Scene& scene);

}  // namespace handcentric::props
