#include "handcentric/core/so3.hpp"

#include <algorithm>
#include <cmath>

namespace handcentric::so3 {
namespace {

// Below this angle exp() uses Taylor series: the first omitted term is phi^6 ~ 1e-24, far
// below double rounding, while the closed forms lose digits to cancellation in 1 - cos(phi).
constexpr double kExpSeriesAngle = 1e-4;
// Below this |sin(phi)| log() uses the series of phi / sin(phi).
constexpr double kLogSeriesSine = 1e-4;
// cos(phi) below this (phi > ~2.5 rad) switches log() to the symmetric-part axis: there
// sin(phi) < 0.6 and dividing the skew part by it would amplify its rounding error.
constexpr double kNearPiCosine = -0.8;
constexpr double kPi = 3.141592653589793238462643383279502884;
// Above this squared angle (|r| > 1e150) exp() works from the unit axis: phi^2 and the products
// b x y of the closed form overflow near |r| ~ 1e154.
constexpr double kLargestSquaredAngle = 1e300;

// phi in [0, pi] from sin(phi) >= 0 and cos(phi), each through a well-conditioned function:
// asin where |cos| >= 0.8 (d asin / ds = 1 / |cos| <= 1.25), acos in between (d acos / dc =
// 1 / sin <= 1.67). Both are about twice as fast as atan2 in glibc, and neither is ever used
// near its singular end (acos near +-1, asin near 1), which is what makes acos-based logs
// inaccurate near 0 and pi.
double angle_from(double sine, double cosine) {
  sine = std::min(sine, 1.0);  // rounding of a unit-norm skew part may exceed 1
  if (cosine >= 0.8) return std::asin(sine);
  if (cosine > -0.8) return std::acos(cosine);
  return kPi - std::asin(sine);
}

// The skew part of R: (R - R^T)/2 = sin(phi) [v]x, returned as sin(phi) v.
Eigen::Vector3d skew_vector(const Eigen::Matrix3d& R) {
  return 0.5 * Eigen::Vector3d(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
}

// R = I + sin(phi) [u]x + (1 - cos(phi)) [u]x^2 for the unit axis u, with sin(phi) = 2 s c and
// 1 - cos(phi) = 2 s^2 of the half angle. Takes s = sin(phi / 2), c = cos(phi / 2).
Eigen::Matrix3d rodrigues_unit_axis(const Eigen::Vector3d& u, double s, double c) {
  const double sine = 2.0 * s * c, versine = 2.0 * s * s;
  Eigen::Matrix3d R = versine * (u * u.transpose());
  R.diagonal().array() += 1.0 - versine;
  R(0, 1) -= sine * u.z();
  R(1, 0) += sine * u.z();
  R(0, 2) += sine * u.y();
  R(2, 0) -= sine * u.y();
  R(1, 2) -= sine * u.x();
  R(2, 1) += sine * u.x();
  return R;
}

}  // namespace

Eigen::Vector3d unit_axis_and_half_angle(const Eigen::Vector3d& r, double& half_angle) {
  // Scaled by the largest component first: |r|^2 overflows above ~1.3e154 and underflows below
  // ~1.5e-154, and |r| itself exceeds DBL_MAX when every component is near it, but r / max|r_i|
  // has norm in [1, sqrt(3)] and half the angle, max|r_i| / 2 * that norm, is always finite.
  const double largest = r.cwiseAbs().maxCoeff();
  if (!(largest > 0.0)) {
    half_angle = 0.0;
    return Eigen::Vector3d::UnitX();
  }
  const Eigen::Vector3d scaled = r / largest;
  const double norm = scaled.norm();
  half_angle = (0.5 * largest) * norm;
  return scaled / norm;
}

Eigen::Matrix3d hat(const Eigen::Vector3d& w) {
  Eigen::Matrix3d W;
  W << 0.0, -w.z(), w.y(),  //
      w.z(), 0.0, -w.x(),   //
      -w.y(), w.x(), 0.0;
  return W;
}

Eigen::Matrix3d exp(const Eigen::Vector3d& r) {
  const double phi2 = r.squaredNorm();
  if (phi2 > kLargestSquaredAngle) {
    // |r| > 1e150: phi^2 is near overflow (or past it) and the products below would be inf.
    // The angle wraps modulo 2 pi; half of it is finite for every finite r.
    double half = 0.0;
    const Eigen::Vector3d u = unit_axis_and_half_angle(r, half);
    double s, c;
    ::sincos(half, &s, &c);
    return rodrigues_unit_axis(u, s, c);
  }
  double a;  // sin(phi) / phi
  double b;  // (1 - cos(phi)) / phi^2
  if (phi2 < kExpSeriesAngle * kExpSeriesAngle) {
    a = 1.0 - phi2 * (1.0 / 6.0) * (1.0 - phi2 * (1.0 / 20.0));
    b = 0.5 - phi2 * (1.0 / 24.0) * (1.0 - phi2 * (1.0 / 30.0));
  } else {
    // One sin/cos pair of the half angle (compiled to a single sincos call):
    // sin(phi) = 2 s c and 1 - cos(phi) = 2 s^2, which has no cancellation near phi = 0.
    const double phi = std::sqrt(phi2);
    const double inv_phi = 1.0 / phi;  // before the call, so the division overlaps it
    const double half = 0.5 * phi;
    double s, c;
    ::sincos(half, &s, &c);  // glibc: both in one call
    a = 2.0 * s * c * inv_phi;
    b = 2.0 * (s * inv_phi) * (s * inv_phi);
  }
  // R = I + a [r]x + b [r]x^2, with [r]x^2 = r r^T - phi^2 I, written out.
  Eigen::Matrix3d R;
  const double x = r.x(), y = r.y(), z = r.z();
  const double bxy = b * x * y, bxz = b * x * z, byz = b * y * z;
  R(0, 0) = 1.0 - b * (y * y + z * z);
  R(1, 1) = 1.0 - b * (x * x + z * z);
  R(2, 2) = 1.0 - b * (x * x + y * y);
  R(0, 1) = bxy - a * z;
  R(1, 0) = bxy + a * z;
  R(0, 2) = bxz + a * y;
  R(2, 0) = bxz - a * y;
  R(1, 2) = byz - a * x;
  R(2, 1) = byz + a * x;
  return R;
}

double angle(const Eigen::Matrix3d& R) {
  const double cosine = 0.5 * (R.trace() - 1.0);
  return angle_from(skew_vector(R).norm(), cosine);
}

Eigen::Vector3d log(const Eigen::Matrix3d& R) {
  const Eigen::Vector3d sin_axis = skew_vector(R);  // sin(phi) v
  const double sine = sin_axis.norm();
  const double cosine = 0.5 * (R.trace() - 1.0);
  const double inv_sine =
      1.0 / sine;  // before the call, so the division overlaps it (inf at 0: unused)
  const double phi = angle_from(sine, cosine);

  if (cosine > kNearPiCosine) {
    // r = phi / sin(phi) * sin(phi) v; series where sin(phi) ~ phi is tiny.
    const double scale = sine < kLogSeriesSine
                             ? 1.0 + phi * phi * (1.0 / 6.0) * (1.0 + (7.0 / 60.0) * phi * phi)
                             : phi * inv_sine;
    return scale * sin_axis;
  }

  // Near pi: (R + R^T)/2 - cos(phi) I = (1 - cos(phi)) v v^T. Take the column with the largest
  // diagonal entry (the largest |v_i|), so the division below is by at least 1/sqrt(3).
  const double one_minus_cos = 1.0 - cosine;  // in [1.8, 2]: no cancellation
  Eigen::Matrix3d B = 0.5 * (R + R.transpose());
  B.diagonal().array() -= cosine;
  Eigen::Index i = 0;
  B.diagonal().maxCoeff(&i);
  Eigen::Vector3d axis = B.col(i) / std::sqrt(B(i, i) * one_minus_cos);  // v, with v_i > 0
  axis.normalize();
  // The skew part carries the sign; when it is exactly zero (phi = pi) the v_i > 0 choice above
  // is the documented canonical sign: the largest-magnitude component is positive.
  if (axis.dot(sin_axis) < 0.0) axis = -axis;
  return phi * axis;
}

}  // namespace handcentric::so3
