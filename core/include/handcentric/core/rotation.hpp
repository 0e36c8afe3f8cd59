#pragma once
// Rotation: a validated element of SO(3), stored as a 3x3 matrix (double).
//
// Named constructors validate and throw InvalidRotation naming the offending value:
// non-finite entries, |R^T R - I|_F > kOrthonormalityTolerance, det(R) < 0, a zero quaternion.
// from_matrix_unchecked() is the fast path for inner loops whose inputs are rotations by
// construction (products of rotations, exp of a finite vector): it checks nothing.
#include <Eigen/Core>

namespace handcentric {

class Rotation {
 public:
  /// |R^T R - I|_F above this is rejected by from_matrix().
  static constexpr double kOrthonormalityTolerance = 1e-9;

  /// The identity.
  Rotation() : world_R_body_(Eigen::Matrix3d::Identity()) {}

  static Rotation identity() { return Rotation(); }

  /// Validating: throws InvalidRotation for non-finite, non-orthonormal or det = -1 input.
  static Rotation from_matrix(const Eigen::Matrix3d& R);

  /// Unchecked fast path for inner loops: R must already be a rotation matrix.
  static Rotation from_matrix_unchecked(const Eigen::Matrix3d& R) noexcept { return Rotation(R); }

  /// The rotation nearest to M in the Frobenius norm (SVD projection, det fixed to +1), for M of
  /// any scale. Throws InvalidRotation for non-finite or rank-deficient M (smallest singular
  /// value at most 1e-12 times the largest).
  static Rotation nearest(const Eigen::Matrix3d& M);

  /// From a quaternion w + xi + yj + zk of any nonzero finite norm, 1e-300 or 1e300 alike
  /// (normalized here).
  /// Throws InvalidRotation for a zero or non-finite quaternion.
  static Rotation from_quaternion(double w, double x, double y, double z);

  /// exp of a rotation vector r = phi v (any finite r; |r| > pi wraps). Throws for non-finite r.
  static Rotation exp(const Eigen::Vector3d& rotation_vector);

  /// Rotation by `angle` radians about world z: the planar SE(2) rotations.
  static Rotation about_z(double angle);

  const Eigen::Matrix3d& matrix() const { return world_R_body_; }

  /// The rotation vector r(R) = phi v, phi in [0, pi] (see so3.hpp for the canonical sign at pi).
  Eigen::Vector3d log() const;

  /// The rotation angle phi in [0, pi].
  double angle() const;

  Rotation inverse() const { return Rotation(world_R_body_.transpose()); }

  /// this * other.
  Rotation operator*(const Rotation& other) const {
    return Rotation(world_R_body_ * other.world_R_body_);
  }

  /// R v.
  Eigen::Vector3d operator*(const Eigen::Vector3d& v) const { return world_R_body_ * v; }

  /// this^{-1} * other = R^T R_other, without forming the inverse (eq. 2's R_0^T R_k).
  Rotation inverse_compose(const Rotation& other) const {
    return Rotation(world_R_body_.transpose() * other.world_R_body_);
  }

 private:
  explicit Rotation(const Eigen::Matrix3d& R) : world_R_body_(R) {}
  Eigen::Matrix3d world_R_body_;
};

/// |A - B|_F of the two matrices: 0 only for the same rotation.
double distance(const Rotation& a, const Rotation& b);

}  // namespace handcentric
