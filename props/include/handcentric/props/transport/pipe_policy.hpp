#pragma once
// A policy written in any language, audited over a pipe (`handcentric audit --policy-exec`,
// docs/AUDIT.md): a PluginConnection that sends the observation and a noise vector and reads
// back the world chunk T_1..T_K (plugin_protocol.hpp, "policy"). The first request is a probe; a
// hello may name extra poses and scalars and ask for a noise length other than 256. Answers are
// cached by request. Not thread-safe.
//
// It is also a BatchPolicy (batch.hpp): a plug-in whose hello declares "batch": B gets the
// observations of an act_batch call not yet answered in batched requests of up to B, of any
// shapes (mixed_shapes(): the plug-in's helper calls its function once per shape), and, after
// the hello, every request as a batched one (act() sends a batch of one).
// Without "batch", act_batch asks one observation at a time, as act does. A hello that also
// offers "encodings": ["base64"] gets the batched lines' arrays encoded (plugin_protocol.hpp).
#include <string>
#include <unordered_map>
#include <vector>

#include "handcentric/props/transport/batch.hpp"
#include "handcentric/props/transport/plugin_connection.hpp"
#include "handcentric/props/noisy_policy.hpp"

namespace handcentric::props {

class PipePolicy final : public NoisyPolicy, public BatchPolicy {
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
  /// The chunk of each (observation, noise): cached ones from the cache, the others asked in
  /// batches of batch_size() observations of any shapes (one at a time when the plug-in does not
  /// batch).
  /// A batched line may mix shapes (docs/AUDIT.md, "--exec"): fewer round trips.
  /// Asked past the cache (the preflight, preflight.hpp): each request goes to the plug-in.
  std::vector<std::vector<RigidTransform>> act_fresh(
      const std::vector<const Scene*>& observations,
      const std::vector<const Eigen::VectorXd*>& noises) const override;
  std::vector<std::vector<RigidTransform>> act_batch_fresh(
      const std::vector<const Scene*>& observations,
      const std::vector<const Eigen::VectorXd*>& noises) const override {
    return act_fresh(observations, noises);
  }
  bool mixed_shapes() const override { return true; }
  std::vector<std::vector<RigidTransform>> act_batch(
      const std::vector<const Scene*>& observations,
      const std::vector<const Eigen::VectorXd*>& noises) const override;
  /// The hello's "batch" (the most observations per request), 0 when the plug-in does not batch.
  int batch_size() const { return capabilities().batch; }

  /// The scene of the handshake's first request instead of the built-in probe (the hand at the
  /// origin): an audit on recorded observations sends their first, so that the plug-in meets
  /// the parts it will be sent (held arrays, extra poses) from its first request on. Call it
  /// before the handshake runs.
  void use_probe(Scene probe) { probe_ = std::move(probe); }

  /// The handshake's result (runs it if it has not run).
  const PluginCapabilities& capabilities() const;
  int requests_sent() const { return connection_.requests_sent(); }

 private:
  Scene with_extras(const Scene& scene) const;
  /// The cache's key of (observation, noise), after checking both.
  std::string key(const Scene& observation, const Eigen::VectorXd& noise) const;
  /// One request; a batch of one (in the hello's encoding) when the plug-in batches.
  PluginReply exchange_one(const Scene& observation, const Eigen::VectorXd& noise) const;
  /// A policy request, with the images of the hello's cameras when it declared some.
  std::string request_body(const Scene& observation, const Eigen::VectorXd& noise,
                           NumberEncoding encoding = NumberEncoding::text) const;
  /// Checks the chunk length of the answer to `where` and caches it under `key`.
  const std::vector<RigidTransform>& remember(std::string key, PluginReply reply,
                                              const std::string& where) const;

  std::vector<std::string> forced_extra_poses_, forced_scalars_;
  mutable PluginConnection connection_;
  mutable std::optional<PluginCapabilities> capabilities_;
  std::optional<Scene> probe_;  ///< use_probe()'s scene
  mutable std::unordered_map<std::string, std::vector<RigidTransform>> cache_;
  mutable bool past_cache_ = false;  ///< during act_fresh: no answer is taken from cache_
  mutable std::size_t chunk_length_ = 0;
};

/// `plugin` as the checks ask it: in batched requests of its hello's size (BatchedPolicy) when it
/// answers batches, else one observation per request. Runs the handshake if it has not run.
std::shared_ptr<const NoisyPolicy> as_checked(std::shared_ptr<const PipePolicy> plugin);

}  // namespace handcentric::props
