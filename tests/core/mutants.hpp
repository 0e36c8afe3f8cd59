#pragma once
// Planted faults for the core suite: each property below is also run on one of these and must
// fail there, so that a property that cannot fail is caught.
#include <Eigen/Core>
#include <Eigen/LU>  // determinant
#include <algorithm>
#include <cmath>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/rotation.hpp"
#include "handcentric/core/so3.hpp"

namespace handcentric::test {

/// The library's log as a plain function, the control beside the planted faults below.
inline Eigen::Vector3d real_log(const Eigen::Matrix3d& R) {
  return so3::log(R);
}

/// The textbook log: phi = acos((tr R - 1)/2), r = phi / (2 sin phi) vee(R - R^T).
/// Loses all accuracy near pi (divides by sin phi) and near 0 (acos of ~1).
inline Eigen::Vector3d naive_log(const Eigen::Matrix3d& R) {
  const double c = std::clamp(0.5 * (R.trace() - 1.0), -1.0, 1.0);
  const double phi = std::acos(c);
  if (phi == 0.0) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d v(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  return phi / (2.0 * std::sin(phi)) * v;
}

/// The textbook exp: phi = |r|, R = I + sin(phi)/phi [r]x + (1 - cos(phi))/phi^2 [r]x^2.
/// phi^2 underflows to 0 below |r| ~ 1e-154 (0/0) and [r]x^2 overflows above ~1e154 (sin of inf,
/// 0 * inf): nan on valid rotation vectors.
inline Eigen::Matrix3d textbook_exp(const Eigen::Vector3d& r) {
  const double phi = r.norm();
  if (phi == 0.0) return Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d W = so3::hat(r);
  return Eigen::Matrix3d::Identity() + std::sin(phi) / phi * W +
         (1.0 - std::cos(phi)) / (phi * phi) * W * W;
}

/// SE(3) exp whose V = I + (1 - cos phi)/phi^2 [w]x + (phi - sin phi)/phi^3 [w]x^2 is the
/// textbook one: nan for huge and for tiny (nonzero) omega.
inline RigidTransform textbook_se3_exp(const Twist& twist) {
  const Eigen::Vector3d rho = twist.head<3>(), omega = twist.tail<3>();
  const double phi = omega.norm();
  if (phi == 0.0) return RigidTransform::unchecked(Eigen::Matrix3d::Identity(), rho);
  const Eigen::Matrix3d W = so3::hat(omega);
  const Eigen::Matrix3d V = Eigen::Matrix3d::Identity() + (1.0 - std::cos(phi)) / (phi * phi) * W +
                            (phi - std::sin(phi)) / (phi * phi * phi) * W * W;
  return RigidTransform::unchecked(so3::exp(omega), V * rho);
}

/// Rotation::from_matrix without its finiteness check and with its comparisons written so that
/// nan passes them ("nan > tolerance" is false): accepts a matrix with a nan entry.
inline Rotation lenient_from_matrix(const Eigen::Matrix3d& R) {
  const double error = (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
  if (error > Rotation::kOrthonormalityTolerance) {
    throw InvalidRotation("matrix is not orthonormal: R = " + format_matrix(R) + "; project it");
  }
  if (R.determinant() < 0.0)
    throw InvalidRotation("matrix is a reflection: R = " + format_matrix(R) + "; flip an axis");
  return Rotation::from_matrix_unchecked(R);
}

/// A log whose canonical sign at pi is the opposite of the documented one.
inline Eigen::Vector3d flipped_sign_log(const Eigen::Matrix3d& R) {
  const Eigen::Vector3d r = so3::log(R);
  return so3::angle(R) > 3.14159 ? Eigen::Vector3d(-r) : r;
}

/// hand_centric that forgets R_0^T on the translation (p_k - p_0 instead of R_0^T (p_k - p_0)),
/// but decodes correctly: its round trip must fail.
class ForgetsRotationOnTranslation final : public Representation {
 public:
  std::string name() const override { return "mutant_forgets_R0T"; }
  Eigen::VectorXd encode_actions(const Scene& scene) const override {
    Eigen::VectorXd a = HandCentricRepresentation().encode_actions(scene);
    for (int k = 0; k < scene.chunk_length(); ++k) {
      a.segment<3>(6 * k) =
          scene.world_T_hand_chunk[k].translation() - scene.world_T_hand0().translation();
    }
    return a;
  }
  Eigen::VectorXd encode_observation(const Scene& scene) const override {
    return HandCentricRepresentation().encode_observation(scene);
  }
  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd& a,
                                             const RigidTransform& world_T_hand0) const override {
    return HandCentricRepresentation().decode_actions(a, world_T_hand0);
  }
};

/// hand_centric that uses R_0 where eq. (2) has R_0^T.
class UsesR0ForR0Transpose final : public Representation {
 public:
  std::string name() const override { return "mutant_R0_for_R0T"; }
  Eigen::VectorXd encode_actions(const Scene& scene) const override {
    Eigen::VectorXd a(6 * scene.chunk_length());
    const Eigen::Matrix3d& R0 = scene.world_T_hand0().rotation().matrix();
    for (int k = 0; k < scene.chunk_length(); ++k) {
      const RigidTransform& Tk = scene.world_T_hand_chunk[k];
      a.segment<3>(6 * k) = R0 * (Tk.translation() - scene.world_T_hand0().translation());
      a.segment<3>(6 * k + 3) = so3::log(R0 * Tk.rotation().matrix());
    }
    return a;
  }
  Eigen::VectorXd encode_observation(const Scene& scene) const override {
    return HandCentricRepresentation().encode_observation(scene);
  }
  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd& a,
                                             const RigidTransform& world_T_hand0) const override {
    return HandCentricRepresentation().decode_actions(a, world_T_hand0);
  }
};

}  // namespace handcentric::test
