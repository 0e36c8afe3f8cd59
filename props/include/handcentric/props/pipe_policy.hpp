#pragma once
// A policy written in any language, audited over a pipe (`handcentric audit --policy-exec`,
// docs/AUDIT.md): a PluginConnection that sends the observation and a noise vector and reads
// back the world chunk T_1..T_K (plugin_protocol.hpp, "policy"). The first request is a probe; a
// hello may name extra poses and scalars and ask for a noise length other than 256. Answers are
// cached by request. Not thread-safe.
#include <string>
#include <unordered_map>
#include <vector>

#include "handcentric/props/plugin_connection.hpp"
#include "handcentric/props/policy_audit.hpp"

namespace handcentric::props {

class PipePolicy final : public NoisyPolicy {
 public:
  /// Starts `command`; names as PipeRepresentation's. Throws InvalidArgument for an empty
  /// command, a timeout <= 0 or a repeated name; PluginError if it cannot start.
  PipePolicy(std::string command, double timeout_seconds,
             std::vector<std::string> extra_pose_names = {},
             std::vector<std::string> scalar_names = {});

  std::string name() const override { return "policy-exec: " + connection_.command(); }
  Eigen::Index noise_dimension() const override;
  /// Throws PluginError for a chunk whose length changes between observations.
  std::vector<RigidTransform> act(const Scene& observation,
                                  const Eigen::VectorXd& noise) const override;

  /// The handshake's result (runs it if it has not run).
  const PluginCapabilities& capabilities() const;
  int requests_sent() const { return connection_.requests_sent(); }

 private:
  Scene with_extras(const Scene& scene) const;

  std::vector<std::string> forced_extra_poses_, forced_scalars_;
  mutable PluginConnection connection_;
  mutable std::optional<PluginCapabilities> capabilities_;
  mutable std::unordered_map<std::string, std::vector<RigidTransform>> cache_;
  mutable std::size_t chunk_length_ = 0;
};

}  // namespace handcentric::props
