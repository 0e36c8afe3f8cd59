#pragma once
// Tolerances of the pointwise checks, the scene perturbations that measure a map's own
// rounding, and the near-identity rule (docs/AUDIT.md, "Tolerances and rounding").
//
// Rounding grows with the size of the numbers involved, so a pointwise check first compares
//   error = |f(g * s) - f(s)|_inf   against   floor = REL * (1 + L)
// with L = the scene's length scale: the largest translation of any pose or point of s and of
// g * s (in metres). 1e-9 is ~1e7 double epsilons: far above the rounding of the few products
// a representation takes (~1e-13 at L = 1e3), far below any real symmetry breaking we know of.
// An error above the floor is not yet a "NO": check.hpp compares it with the map's response to
// a rounding-level perturbation of the same scenes (rounding_perturbation) and looks whether it
// survives moving both scenes slightly off the case (nearby_scene): a bin edge does not.
//
// Near identity: a transform g with rotation angle + |p~| / (1 + L) below kNearIdentity moves
// nothing measurably, so a case with such a g cannot show a symmetry. Such cases are still run
// and must still pass (they catch NaNs and blow-ups at the identity), but they are not counted
// in a verdict's cases, and a check holds only with at least one far case.
#include <random>
#include <string>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/scene.hpp"

namespace handcentric::props {

constexpr double kRelativeTolerance = 1e-9;

// Unit roundoff of the arithmetic a map is computed in: what one rounding can do, relative.
constexpr double kFloat64UnitRoundoff = 0x1p-53;
constexpr double kFloat32UnitRoundoff = 0x1p-24;
constexpr double kFloat16UnitRoundoff = 0x1p-11;  // IEEE half: 11 significant bits
constexpr double kBfloat16UnitRoundoff = 0x1p-8;  // bfloat16: 8 significant bits

// The float32 floor (`--precision float32`): 64 units of float32 rounding, 3.8e-6 (1 + L). A pose
// pipeline in float32 rounds its inputs and each of a few products at the scene's length scale
// (~6e-8 (1 + L) each), which the floor covers; what rounds worse (a rotation vector through
// acos near pi loses up to sqrt(2^-24) = 2.4e-4 rad, a network that amplifies its input's
// rounding) is measured per case instead (check.hpp). The floor stays far below a task's
// clearance (1 mm for the peg): a leak of 0.6 mm at L = 10 m is 14 times over it.
constexpr double kFloat32RelativeTolerance = 64 * kFloat32UnitRoundoff;

// The floor of the 16-bit formats (`precision="bfloat16"` or `"float16"`): 2^-7 (1 + L), two
// units of bfloat16 rounding, 0.8% of the scene's size. 64 units, as for float32, would be a
// quarter of it and hide any leak; a 16-bit pipeline's rounding above this floor is measured per
// case instead (the rounding probe at the format's unit, check.hpp). What such a "yes" cannot
// see is a breaking below 2^-7 (1 + L).
constexpr double kHalfPrecisionRelativeTolerance = 0x1p-7;
constexpr double kNearIdentity = 1e-6;

// A case whose error is at most kRoundingMultiple times the map's measured response to a
// rounding-level perturbation is rounding, provided that response is itself rounding-sized:
// at most sqrt(u) (1 + L), the worst loss of a well-posed pose pipeline (acos near 0 or pi).
constexpr double kRoundingMultiple = 8.0;
// Units of rounding each input coordinate moves by in rounding_perturbation.
constexpr double kRoundingPerturbationUlps = 4.0;

/// How far a policy's output pose may be from a rigid transform at float64: |R^T R - I|_max,
/// |det R - 1| and the last row's distance from 0 0 0 1. A rotation block scaled or sheared by a
/// bug is off by O(1).
constexpr double kOutputPoseTolerance = 1e-5;

/// The output pose check at unit roundoff u: max(kOutputPoseTolerance, 2 sqrt(u)), twice the
/// worst loss of a well-posed pose computation (the rounding cap of check.hpp): 4.9e-4 for
/// float32 (a 6D rotation orthonormalized in float32 was seen at 1.4e-5), 0.044 for float16,
/// 0.125 for bfloat16 (R_0 R_k multiplied in bfloat16 was seen at 0.068, 17 units), far below a
/// bug's O(1).
double output_pose_tolerance(double unit_roundoff);

/// Empty when M = [[R, p], [0, 0, 0, 1]] with R a rotation within `tolerance` (and every entry
/// finite); else one sentence with the offending numbers.
std::string pose_defect(const Eigen::Matrix4d& M, double tolerance = kOutputPoseTolerance);

/// L: the largest translation norm of any pose or point of the scene (0 for an empty scene).
double length_scale(const Scene& scene);

/// relative * (1 + max(L(s), L(g * s))); relative = kRelativeTolerance unless a check's
/// options say otherwise (e.g. 1e-4 for a network computed in float).
double pointwise_tolerance(const Scene& scene, const Scene& moved,
                           double relative = kRelativeTolerance);

/// The largest response to rounding that still counts as rounding: sqrt(u) (1 + L).
double rounding_cap(double unit_roundoff, double length_scale);

/// How far nearby_scene moves a scene off a case, relative: max(1e-9, 1e3 u). Far above the
/// rounding of g * s (a few u (1 + L)), so a case that sat on a bin edge leaves it on both
/// sides alike; far below any feature a policy resolves (1e-9 m for double, 6e-5 for float32).
double off_case_scale(double unit_roundoff);

/// `scene` with every input moved by a few units of rounding: each translation and point
/// coordinate x -> x (1 + 4 u xi) and each rotation R -> R exp(4 u omega) (xi = +-1, |omega| =
/// 1, random), each scalar likewise. What the map does to it is its own rounding response.
/// `planar` (the 2D task's scenes): omega along z, so that the scene stays in the plane.
Scene rounding_perturbation(const Scene& scene, double unit_roundoff, std::mt19937_64& rng,
                            bool planar = false);

/// `scene` moved slightly off: each pose T -> T exp(rho, omega) with |rho| = eta (1 + L(s)) and
/// |omega| = eta, each point by eta (1 + L) and each scalar by eta max(1, |x|), in random
/// directions (in the plane, omega along z, when `planar`). Applied before g, so
/// g * nearby_scene(s) is the moved case.
Scene nearby_scene(const Scene& scene, double eta, std::mt19937_64& rng, bool planar = false);

/// angle(R~) + |p~| / (1 + L(s)): how far g is from the identity, relative to the scene.
double distance_from_identity(const RigidTransform& g, const Scene& scene);

/// distance_from_identity(g, scene) < kNearIdentity.
bool near_identity(const RigidTransform& g, const Scene& scene);

}  // namespace handcentric::props
