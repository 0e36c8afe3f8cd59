#pragma once
// RigidTransform: an element of SE(3), T = [R | p], read "world_T_body": it maps body
// coordinates to world coordinates, x_world = R x_body + p.
//
// Planar SE(2) is the subgroup planar(theta, x, y): rotation about z by theta, translation
// (x, y, 0).
//
// Validating constructors throw InvalidTransform (non-finite translation, bad homogeneous row)
// or InvalidRotation (bad rotation block); unchecked() is the fast path for inner loops whose
// inputs are rigid by construction.
//
// Valid input, on which every function here returns finite values (tests/core/test_numerics.cpp):
// rotations that pass Rotation::from_matrix, translations (and twists' rho) with coordinates up
// to 1e150 in magnitude, so that sums and products of two stay far from overflow, and any finite
// rotation vector omega (exp wraps it). Accuracy, with so3.hpp's constants:
//   - |exp(log(T)) - T| (distance below) <= so3::kRoundTripError * (1 + |p|);
//   - |log(exp(xi)) - xi| <= so3::kRoundTripError * (1 + |rho|)
//     when |omega| <= pi - so3::kSignAmbiguity.
#include <Eigen/Core>

#include "handcentric/core/rotation.hpp"

namespace handcentric {

/// A twist (rho, omega): translation part first, then the rotation vector (manif's order).
using Twist = Eigen::Matrix<double, 6, 1>;

class RigidTransform {
 public:
  /// The identity.
  RigidTransform() : translation_(Eigen::Vector3d::Zero()) {}

  /// Validating: throws InvalidTransform for a non-finite translation.
  RigidTransform(const Rotation& rotation, const Eigen::Vector3d& translation);

  static RigidTransform identity() { return RigidTransform(); }

  /// Unchecked fast path for inner loops: R must be a rotation matrix and p finite.
  static RigidTransform unchecked(const Eigen::Matrix3d& R, const Eigen::Vector3d& p) noexcept {
    RigidTransform T;
    T.rotation_ = Rotation::from_matrix_unchecked(R);
    T.translation_ = p;
    return T;
  }

  /// From a homogeneous 4x4 matrix; validates the rotation block, translation, last row.
  static RigidTransform from_matrix(const Eigen::Matrix4d& matrix);

  /// A pure translation.
  static RigidTransform from_translation(const Eigen::Vector3d& translation);

  /// Planar SE(2) embedded in SE(3): rotation about z by theta, translation (x, y, 0).
  static RigidTransform planar(double theta, double x, double y);

  /// exp of a twist (rho, omega). Throws InvalidTransform for a non-finite twist.
  static RigidTransform exp(const Twist& twist);

  /// The twist (rho, omega) with |omega| in [0, pi]: exp(log(T)) = T.
  Twist log() const;

  const Rotation& rotation() const { return rotation_; }
  const Eigen::Vector3d& translation() const { return translation_; }

  /// The homogeneous 4x4 matrix.
  Eigen::Matrix4d matrix() const;

  /// a * b: first b, then a (a_T_c = a_T_b * b_T_c).
  RigidTransform operator*(const RigidTransform& other) const {
    const Eigen::Matrix3d& R = rotation_.matrix();
    RigidTransform out;
    out.rotation_ = Rotation::from_matrix_unchecked(R * other.rotation_.matrix());
    out.translation_.noalias() = R * other.translation_;
    out.translation_ += translation_;
    return out;
  }

  /// Acts on a point: R x + p.
  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const {
    return rotation_.matrix() * point + translation_;
  }

  /// T^{-1} = [R^T | -R^T p].
  RigidTransform inverse() const {
    const Eigen::Matrix3d Rt = rotation_.matrix().transpose();
    return unchecked(Rt, -(Rt * translation_));
  }

  /// this^{-1} * other without forming the inverse: eq. (1), hand0_T_handk = world_T_hand0^{-1}
  /// world_T_handk = [R_0^T R_k | R_0^T (p_k - p_0)] (eq. 2).
  RigidTransform inverse_compose(const RigidTransform& other) const {
    const Eigen::Matrix3d Rt = rotation_.matrix().transpose();
    return unchecked(Rt * other.rotation_.matrix(), Rt * (other.translation_ - translation_));
  }

 private:
  Rotation rotation_;
  Eigen::Vector3d translation_;
};

/// A size-aware distance: |R_a - R_b|_F + |p_a - p_b|.
double distance(const RigidTransform& a, const RigidTransform& b);

}  // namespace handcentric
