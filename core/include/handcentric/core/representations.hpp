#pragma once
// The four built-in representations of the paper, and a registry by name.
//
//   absolute      : a_k = (p_k, r(R_k))                               Sec. 2.1, App. A.1
//   relative      : (p_k - p_0, r(R_0^T R_k))                          Sec. 2.1
//   relative_diff : (p_k - p_0, r(R_k) - r(R_0))                       App. A.2, eq. (14)
//   hand_centric  : hand0_T_handk = T_0^{-1} T_k = (R_0^T (p_k - p_0), r(R_0^T R_k))
//                                                                       eqs. (1)-(3)
// Observations: world-frame proprioception (p_{-h}, r(R_{-h})) for absolute, relative and
// relative_diff; hand-centric proprioception T_0^{-1} T_{-h} (eq. 3) for hand_centric.
// Sec. 2.1 and App. A.2 define "relative" differently; both are here, under their own names.
#include <memory>
#include <string>
#include <vector>

#include "handcentric/core/representation.hpp"

namespace handcentric {

class AbsoluteRepresentation final : public Representation {
 public:
  std::string name() const override { return "absolute"; }
  Eigen::VectorXd encode_actions(const Scene& scene) const override;
  Eigen::VectorXd encode_observation(const Scene& scene) const override;
  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd& actions,
                                             const RigidTransform& world_T_hand0) const override;
};

class RelativeRepresentation final : public Representation {
 public:
  std::string name() const override { return "relative"; }
  Eigen::VectorXd encode_actions(const Scene& scene) const override;
  Eigen::VectorXd encode_observation(const Scene& scene) const override;
  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd& actions,
                                             const RigidTransform& world_T_hand0) const override;
};

class RelativeDiffRepresentation final : public Representation {
 public:
  std::string name() const override { return "relative_diff"; }
  Eigen::VectorXd encode_actions(const Scene& scene) const override;
  Eigen::VectorXd encode_observation(const Scene& scene) const override;
  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd& actions,
                                             const RigidTransform& world_T_hand0) const override;
};

class HandCentricRepresentation final : public Representation {
 public:
  std::string name() const override { return "hand_centric"; }
  Eigen::VectorXd encode_actions(const Scene& scene) const override;
  Eigen::VectorXd encode_observation(const Scene& scene) const override;
  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd& actions,
                                             const RigidTransform& world_T_hand0) const override;
};

/// "absolute", "relative", "relative_diff", "hand_centric", in that order.
std::vector<std::string> builtin_representation_names();

/// A built-in by name; throws InvalidArgument naming the value and the valid names.
std::unique_ptr<Representation> make_representation(const std::string& name);

}  // namespace handcentric
