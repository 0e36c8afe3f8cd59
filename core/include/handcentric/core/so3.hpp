#pragma once
// SO(3) exponential and logarithm on raw 3x3 matrices (the unchecked math behind Rotation).
//
// The rotation vector of Sec. 2.1 / App. A.3 is r(R) = phi v with angle phi in [0, pi] and unit
// axis v. log() is accurate over the whole range:
//   - near phi = 0 it uses the series phi / sin(phi) = 1 + phi^2/6 + 7 phi^4/360;
//   - near phi = pi it takes no acos and divides by no sin(phi): the axis comes from the column
//     of the symmetric part (R + R^T)/2 - cos(phi) I = (1 - cos(phi)) v v^T with the largest
//     diagonal, and its sign from the skew part (R - R^T)/2 = sin(phi) [v]x;
//   - the angle is asin(sin phi) where |cos phi| >= 0.8 and acos(cos phi) in between: each only
//     where it is well conditioned (never acos near 0 or pi).
//
// Canonical sign at exactly pi: r and -r are the same rotation there. When the skew part is
// exactly zero (so it carries no sign), log() returns the axis whose largest-magnitude component
// is positive (the first such component when two tie). Tested in tests/core.
//
// Documented accuracy, for EVERY finite input (tests/core/test_numerics.cpp checks each bound on
// >= 1e5 generated inputs per run, among them angles 0, pi, within 1e-12 of both, |r| up to
// DBL_MAX and float's extremes):
//   - exp(r) is finite with |R^T R - I|_F <= kOrthonormalityError and |det R - 1| <= that too,
//     so it passes Rotation::from_matrix;
//   - log(R) is finite with |log R| <= pi + kAngleSlack, and |exp(log R) - R|_F <= kRoundTripError
//     for R = exp(r);
//   - |log(exp(r)) - r| <= kRoundTripError * min(1, |r|) when |r| <= pi - kSignAmbiguity; for
//     pi - kSignAmbiguity < |r| <= pi, log(exp(r)) is r or its antipode -(2 pi - |r|) r / |r|
//     to that error (the sign of a rotation this close to pi is below double rounding).
// Measured worst cases (2e6 inputs): 4.1e-15, 3.0e-15 and 2.2e-15.
#include <Eigen/Core>

namespace handcentric::so3 {

constexpr double kOrthonormalityError = 1e-14;
constexpr double kRoundTripError = 1e-13;
constexpr double kAngleSlack = 1e-15;
constexpr double kSignAmbiguity = 1e-14;

/// [w]x, the skew matrix with [w]x u = w x u.
Eigen::Matrix3d hat(const Eigen::Vector3d& w);

/// exp([r]x) by Rodrigues' formula, series below an angle of 1e-4. No validation: r must be finite.
/// Any finite r gives a finite rotation, including |r| near or above DBL_MAX (the angle wraps).
Eigen::Matrix3d exp(const Eigen::Vector3d& rotation_vector);

/// The unit axis u of a finite r != 0 and half its angle, |r| / 2, computed without overflow or
/// underflow for every finite r (|r| itself may exceed DBL_MAX). For r = 0: the x axis and 0.
Eigen::Vector3d unit_axis_and_half_angle(const Eigen::Vector3d& rotation_vector,
                                         double& half_angle);

/// The rotation vector r(R), angle in [0, pi]. No validation: R must be a rotation matrix.
Eigen::Vector3d log(const Eigen::Matrix3d& R);

/// The rotation angle of R in [0, pi] (see above). No validation.
double angle(const Eigen::Matrix3d& R);

}  // namespace handcentric::so3
