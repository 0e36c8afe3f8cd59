#include "handcentric/core/rotation.hpp"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <cmath>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/core/so3.hpp"

namespace handcentric {

Rotation Rotation::from_matrix(const Eigen::Matrix3d& R) {
  if (!R.allFinite()) {
    throw InvalidRotation("rotation matrix has a non-finite entry: " + format_matrix(R) +
                          "; pass a finite 3x3 rotation matrix");
  }
  // Written so that nan fails: R^T R of a finite matrix with entries near 1e300 sums +inf and
  // -inf into nan, and "nan > tolerance" is false.
  const double orthonormality_error = (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
  if (!(orthonormality_error <= kOrthonormalityTolerance)) {
    throw InvalidRotation(
        "matrix is not orthonormal: |R^T R - I|_F = " + format_number(orthonormality_error) +
        " > " + format_number(kOrthonormalityTolerance) + " for R = " + format_matrix(R) +
        "; project it with Rotation::nearest(R) if it is a rounded rotation");
  }
  const double determinant = R.determinant();
  if (!(determinant > 0.0)) {
    throw InvalidRotation("matrix is a reflection, det(R) = " + format_number(determinant) +
                          " for R = " + format_matrix(R) +
                          "; a rotation has det +1 (flip one axis to fix the handedness)");
  }
  return Rotation(R);
}

Rotation Rotation::nearest(const Eigen::Matrix3d& M) {
  if (!M.allFinite()) {
    throw InvalidRotation("cannot project a non-finite matrix onto SO(3): " + format_matrix(M));
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d singular = svd.singularValues();
  // Relative, so that a scaled rotation (1e-20 R or 1e20 R) projects to R like R itself.
  if (!(singular(2) > 1e-12 * singular(0))) {
    throw InvalidRotation("cannot project a rank-deficient matrix onto SO(3): singular values " +
                          format_matrix(singular) + " of " + format_matrix(M));
  }
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return Rotation(svd.matrixU() * D * svd.matrixV().transpose());
}

Rotation Rotation::from_quaternion(double w, double x, double y, double z) {
  const Eigen::Vector4d given(w, x, y, z);
  if (!given.allFinite()) {
    throw InvalidRotation("quaternion has a non-finite entry: (w, x, y, z) = " +
                          format_matrix(given));
  }
  Eigen::Vector4d q = given;
  double norm2 = q.squaredNorm();
  if (!(norm2 >= 1e-200 && norm2 <= 1e200)) {
    // |q|^2 would overflow (|q| > ~1e154) or lose digits to underflow: R(q) = R(q / c) for any
    // c > 0, so divide by the largest component first. Only here, so other quaternions keep
    // their bits.
    const double largest = q.cwiseAbs().maxCoeff();
    if (!(largest > 0.0)) {
      throw InvalidRotation("quaternion (w, x, y, z) = " + format_matrix(given) +
                            " is zero; a rotation needs a nonzero quaternion");
    }
    q /= largest;
    norm2 = q.squaredNorm();
  }
  w = q[0], x = q[1], y = q[2], z = q[3];
  // R(q) = M(q) / |q|^2 with M quadratic in q: orthonormal for any nonzero q.
  const double s = 2.0 / norm2;
  Eigen::Matrix3d R;
  R << 1 - s * (y * y + z * z), s * (x * y - w * z), s * (x * z + w * y),  //
      s * (x * y + w * z), 1 - s * (x * x + z * z), s * (y * z - w * x),   //
      s * (x * z - w * y), s * (y * z + w * x), 1 - s * (x * x + y * y);
  return Rotation(R);
}

Rotation Rotation::exp(const Eigen::Vector3d& rotation_vector) {
  if (!rotation_vector.allFinite()) {
    throw InvalidRotation("rotation vector has a non-finite entry: " +
                          format_matrix(rotation_vector));
  }
  return Rotation(so3::exp(rotation_vector));
}

Rotation Rotation::about_z(double angle) {
  if (!std::isfinite(angle)) {
    throw InvalidRotation("rotation angle about z is not finite: " + format_number(angle));
  }
  const double c = std::cos(angle), s = std::sin(angle);
  Eigen::Matrix3d R;
  R << c, -s, 0, s, c, 0, 0, 0, 1;
  return Rotation(R);
}

Eigen::Vector3d Rotation::log() const {
  return so3::log(world_R_body_);
}

double Rotation::angle() const {
  return so3::angle(world_R_body_);
}

double distance(const Rotation& a, const Rotation& b) {
  return (a.matrix() - b.matrix()).norm();
}

}  // namespace handcentric
