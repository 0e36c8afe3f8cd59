#include "handcentric/core/rigid_transform.hpp"

#include <cmath>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/core/so3.hpp"

namespace handcentric {
namespace {

// Below this angle the SE(3) V-matrix coefficients use their Taylor series (cf. so3.cpp).
constexpr double kSeriesAngle = 1e-4;
// Above this squared angle (|omega| > 1e150) exp() works from the unit axis (as so3::exp does).
constexpr double kLargestSquaredAngle = 1e300;

// V = I + b [w]x + c [w]x^2 maps rho to the translation: p = V rho.
// b = (1 - cos phi) / phi^2, c = (phi - sin phi) / phi^3.
Eigen::Matrix3d left_jacobian(const Eigen::Vector3d& omega) {
  const double phi2 = omega.squaredNorm();
  if (phi2 > kLargestSquaredAngle) {
    // |omega| > 1e150: [w]x^2 would overflow. With the unit axis u, b [w]x = (1 - cos phi) / phi
    // [u]x and c [w]x^2 = (1 - sin(phi) / phi) [u]x^2; phi = 2 * half may be inf (then both
    // quotients are 0), never nan.
    double half = 0.0;
    const Eigen::Vector3d u = so3::unit_axis_and_half_angle(omega, half);
    double s, c;
    ::sincos(half, &s, &c);
    const double phi = 2.0 * half;
    const Eigen::Matrix3d U = so3::hat(u);
    return Eigen::Matrix3d::Identity() + (2.0 * s * s / phi) * U +
           (1.0 - 2.0 * s * c / phi) * U * U;
  }
  const double phi = std::sqrt(phi2);
  double b, c;
  if (phi < kSeriesAngle) {
    b = 0.5 - phi2 / 24.0;
    c = 1.0 / 6.0 - phi2 / 120.0;
  } else {
    const double half_sin = std::sin(0.5 * phi) / phi;
    b = 2.0 * half_sin * half_sin;
    c = (phi - std::sin(phi)) / (phi2 * phi);
  }
  const Eigen::Matrix3d W = so3::hat(omega);
  return Eigen::Matrix3d::Identity() + b * W + c * W * W;
}

// V^{-1} = I - [w]x / 2 + d [w]x^2, d = (1 - phi sin(phi) / (2 (1 - cos phi))) / phi^2.
// Well defined on [0, pi]: 1 - cos(phi) > 0 away from 0, and the series covers 0.
Eigen::Matrix3d inverse_left_jacobian(const Eigen::Vector3d& omega) {
  const double phi2 = omega.squaredNorm();
  const double phi = std::sqrt(phi2);
  double d;
  if (phi < kSeriesAngle) {
    d = 1.0 / 12.0 + phi2 / 720.0;
  } else {
    const double half = 0.5 * phi;
    // phi sin(phi) / (2 (1 - cos phi)) = (phi / 2) cot(phi / 2)
    d = (1.0 - half * std::cos(half) / std::sin(half)) / phi2;
  }
  const Eigen::Matrix3d W = so3::hat(omega);
  return Eigen::Matrix3d::Identity() - 0.5 * W + d * W * W;
}

}  // namespace

RigidTransform::RigidTransform(const Rotation& rotation, const Eigen::Vector3d& translation)
    : rotation_(rotation), translation_(translation) {
  if (!translation.allFinite()) {
    throw InvalidTransform("translation has a non-finite entry: " + format_matrix(translation) +
                           "; pass a finite translation");
  }
}

RigidTransform RigidTransform::from_matrix(const Eigen::Matrix4d& matrix) {
  if (!matrix.allFinite()) {
    throw InvalidTransform("homogeneous matrix has a non-finite entry: " + format_matrix(matrix));
  }
  const Eigen::RowVector4d last_row = matrix.row(3);
  if (last_row != Eigen::RowVector4d(0, 0, 0, 1)) {
    throw InvalidTransform("homogeneous matrix must end in the row [0, 0, 0, 1], got " +
                           format_matrix(last_row.transpose()) + " in " + format_matrix(matrix));
  }
  return RigidTransform(Rotation::from_matrix(matrix.topLeftCorner<3, 3>()),
                        matrix.topRightCorner<3, 1>());
}

RigidTransform RigidTransform::from_translation(const Eigen::Vector3d& translation) {
  return RigidTransform(Rotation::identity(), translation);
}

RigidTransform RigidTransform::planar(double theta, double x, double y) {
  return RigidTransform(Rotation::about_z(theta), Eigen::Vector3d(x, y, 0.0));
}

RigidTransform RigidTransform::exp(const Twist& twist) {
  if (!twist.allFinite()) {
    throw InvalidTransform("twist has a non-finite entry: " + format_matrix(twist));
  }
  const Eigen::Vector3d rho = twist.head<3>();
  const Eigen::Vector3d omega = twist.tail<3>();
  return unchecked(so3::exp(omega), left_jacobian(omega) * rho);
}

Twist RigidTransform::log() const {
  const Eigen::Vector3d omega = rotation_.log();
  Twist twist;
  twist.head<3>() = inverse_left_jacobian(omega) * translation_;
  twist.tail<3>() = omega;
  return twist;
}

Eigen::Matrix4d RigidTransform::matrix() const {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = rotation_.matrix();
  T.topRightCorner<3, 1>() = translation_;
  return T;
}

double distance(const RigidTransform& a, const RigidTransform& b) {
  return distance(a.rotation(), b.rotation()) + (a.translation() - b.translation()).norm();
}

}  // namespace handcentric
