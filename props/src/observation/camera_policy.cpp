#include "handcentric/props/observation/camera_policy.hpp"

#include "handcentric/core/errors.hpp"

namespace handcentric::props {

CameraPolicy::CameraPolicy(std::shared_ptr<const ImagePolicy> policy, CameraRig rig)
    : policy_(std::move(policy)), rig_(std::move(rig)) {
  if (!policy_) throw InvalidArgument("CameraPolicy: the image policy is null; pass a policy");
  rig_.validate();
}

std::vector<RigidTransform> CameraPolicy::act(const Scene& observation,
                                              const Eigen::VectorXd& noise) const {
  return policy_->act(observation, render_views(observation, rig_), noise);
}

}  // namespace handcentric::props
