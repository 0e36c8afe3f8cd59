#pragma once
// A policy that sees images, and the adapter that renders them for the audit: the audited map is
// o -> a(o, images(o), n), so eq. (4) is checked for the camera and the network together. An
// eye-in-hand camera keeps a hand-centric policy equivariant (its images do not change with g);
// a third-person camera does not (camera_rig.hpp).
#include <memory>
#include <string>
#include <vector>

#include "handcentric/core/camera.hpp"
#include "handcentric/props/observation/camera_rig.hpp"
#include "handcentric/props/noisy_policy.hpp"

namespace handcentric::props {

class ImagePolicy {
 public:
  virtual ~ImagePolicy() = default;
  virtual std::string name() const = 0;
  virtual Eigen::Index noise_dimension() const = 0;
  /// T_1..T_K for `observation` and its images (one per rig view, in the rig's order).
  virtual std::vector<RigidTransform> act(const Scene& observation,
                                          const std::vector<CameraImage>& images,
                                          const Eigen::VectorXd& noise) const = 0;
};

/// The NoisyPolicy the audit checks: renders rig's images of each observation, then asks the
/// image policy.
class CameraPolicy final : public NoisyPolicy {
 public:
  /// Throws InvalidArgument for a null policy or a bad rig.
  CameraPolicy(std::shared_ptr<const ImagePolicy> policy, CameraRig rig);
  std::string name() const override { return policy_->name(); }
  Eigen::Index noise_dimension() const override { return policy_->noise_dimension(); }
  std::vector<RigidTransform> act(const Scene& observation,
                                  const Eigen::VectorXd& noise) const override;
  const CameraRig& rig() const { return rig_; }

 private:
  std::shared_ptr<const ImagePolicy> policy_;
  CameraRig rig_;
};

}  // namespace handcentric::props
