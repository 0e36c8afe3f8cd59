#pragma once
// Planted faults for the core suite: each property below is also run on one of these and must
// fail there, so that a property that cannot fail is caught.
#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "handcentric/core/representations.hpp"
#include "handcentric/core/so3.hpp"

namespace handcentric::test {

/// The textbook log: phi = acos((tr R - 1)/2), r = phi / (2 sin phi) vee(R - R^T).
/// Loses all accuracy near pi (divides by sin phi) and near 0 (acos of ~1).
inline Eigen::Vector3d naive_log(const Eigen::Matrix3d& R) {
  const double c = std::clamp(0.5 * (R.trace() - 1.0), -1.0, 1.0);
  const double phi = std::acos(c);
  if (phi == 0.0) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d v(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  return phi / (2.0 * std::sin(phi)) * v;
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
