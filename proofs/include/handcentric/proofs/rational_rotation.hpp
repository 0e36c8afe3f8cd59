#pragma once
// Exact rotations for counterexamples: every entry a rational number, so a counterexample is
// evaluated with no rounding at all.
//
//  - rational_rotation(w, x, y, z): R(q) of quaternion_rotation.hpp for an integer quaternion
//    (entries have denominator |q|^2: q = (2, 1, 0, 0) is the 3-4-5 rotation about x).
//  - quarter_turn(axis, n): n quarter turns about a coordinate axis (entries in {-1, 0, 1}).
//  - exact_rotation_vector(R): r(R) = phi v (Sec. A.3) exactly, for the rotations whose angle is
//    a "nice" multiple of pi: cos(phi) in {1, 1/2, 0, -1/2}, i.e. phi in {0, pi/3, pi/2, 2pi/3}.
//    The result is exact in Q(sqrt(3), pi). The angle pi is refused: r is not unique there.
//    Products of quarter turns (the 24 rotations of the cube) all qualify except those of angle pi.
#include <ginac/ginac.h>

#include "handcentric/proofs/exact_pose.hpp"

namespace handcentric::proofs {

/// R(q) for an integer quaternion. Throws InvalidRotation for q = 0.
GiNaC::matrix rational_rotation(long w, long x, long y, long z);

/// n quarter turns (n * 90 deg, right-handed) about axis 0 (x), 1 (y) or 2 (z).
/// Throws InvalidArgument for another axis.
GiNaC::matrix quarter_turn(int axis, int n);

/// True when every entry is a rational number, R^T R = I and det R = 1, all exactly.
bool is_exact_rotation(const GiNaC::matrix& R);

/// True when every entry of the column is a rational number.
bool is_rational_column(const GiNaC::matrix& v);

/// True when the exact rotation R has angle below pi, i.e. trace R > -1
/// (cos(angle) = (tr R - 1)/2), where r is injective. False for a non-rational matrix.
bool has_angle_below_pi(const GiNaC::matrix& R);

/// r(R) exactly (see above). Throws InvalidRotation when R is not an exact rational rotation,
/// and InvalidArgument naming cos(phi) when the angle has no exact value here (or is pi).
GiNaC::matrix exact_rotation_vector(const GiNaC::matrix& R);

}  // namespace handcentric::proofs
