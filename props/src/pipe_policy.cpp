#include "handcentric/props/pipe_policy.hpp"

namespace handcentric::props {

PipePolicy::PipePolicy(std::string command, double timeout_seconds,
                       std::vector<std::string> extra_pose_names,
                       std::vector<std::string> scalar_names)
    : forced_extra_poses_(std::move(extra_pose_names)),
      forced_scalars_(std::move(scalar_names)),
      connection_(std::move(command), timeout_seconds) {
  require_distinct_names(forced_extra_poses_, "--extra-poses");
  require_distinct_names(forced_scalars_, "--scalars");
}

Scene PipePolicy::with_extras(const Scene& scene) const {
  if (capabilities_)
    return with_named_extras(scene, capabilities_->extra_pose_names, capabilities_->scalar_names);
  return with_named_extras(scene, forced_extra_poses_, forced_scalars_);
}

const PluginCapabilities& PipePolicy::capabilities() const {
  if (capabilities_) return *capabilities_;
  // The probe: the hand at the origin, the default noise.
  Scene probe;
  probe.world_T_hand_history = {RigidTransform::identity()};
  const Eigen::VectorXd noise = fixed_noise(kPolicyNoise, 1);
  PluginReply reply = connection_.exchange(RequestKind::policy,
                                           policy_request_body(with_extras(probe), noise), true);
  PluginCapabilities capabilities;
  if (reply.hello) capabilities = *reply.hello;
  capabilities.extra_pose_names = merged_names(capabilities.extra_pose_names, forced_extra_poses_);
  capabilities.scalar_names = merged_names(capabilities.scalar_names, forced_scalars_);
  if (capabilities.noise == 0) capabilities.noise = kPolicyNoise;
  capabilities_ = capabilities;
  if (reply.hello) {
    const Eigen::VectorXd asked = fixed_noise(capabilities.noise, 1);
    reply = connection_.exchange(RequestKind::policy,
                                 policy_request_body(with_extras(probe), asked), false);
  }
  chunk_length_ = reply.chunk.size();
  return *capabilities_;
}

Eigen::Index PipePolicy::noise_dimension() const {
  return capabilities().noise;
}

std::vector<RigidTransform> PipePolicy::act(const Scene& observation,
                                            const Eigen::VectorXd& noise) const {
  capabilities();
  observation.validate_observation();
  if (noise.size() != noise_dimension()) {
    throw InvalidArgument(name() + " reads " + std::to_string(noise_dimension()) +
                          " noise numbers, got " + std::to_string(noise.size()));
  }
  const std::string body = policy_request_body(observation, noise);
  if (const auto hit = cache_.find(body); hit != cache_.end()) return hit->second;
  PluginReply reply = connection_.exchange(RequestKind::policy, body, false);
  if (reply.chunk.size() != chunk_length_) {
    connection_.fail(
        connection_.who() + " answered policy request " + std::to_string(connection_.last_id()) +
        " with " + std::to_string(reply.chunk.size()) + " poses after " +
        std::to_string(chunk_length_) + " for the probe; the chunk length K must not change");
  }
  if (cache_.size() > 200000) cache_.clear();  // bounded memory over long audits
  return cache_.emplace(body, std::move(reply.chunk)).first->second;
}

}  // namespace handcentric::props
