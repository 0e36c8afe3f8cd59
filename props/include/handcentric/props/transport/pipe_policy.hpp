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
#include <memory>
#include <optional>
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

  /// Every output of an answer, in the interface's order (one when the plug-in answers a
  /// "chunk"), each as poses: an invariant output's numbers embedded at the observation's T_0
  /// (named_output.hpp).
  using Answer = std::vector<std::vector<RigidTransform>>;
  /// Output `output` of the answer to each (observation, noise); with `executed` (another
  /// output), that output's first pose ahead of it, for the closed loop (compared_from = 1).
  /// `fresh`: past the cache.
  std::vector<std::vector<RigidTransform>> chunks(
      const std::vector<const Scene*>& observations,
      const std::vector<const Eigen::VectorXd*>& noises, bool fresh, std::size_t output = 0,
      std::optional<std::size_t> executed = std::nullopt) const;
  /// The answers to each (observation, noise), as act_batch asks them; `fresh`: past the cache.
  std::vector<Answer> answers(const std::vector<const Scene*>& observations,
                              const std::vector<const Eigen::VectorXd*>& noises, bool fresh) const;

  /// An answer with the values of the pipeline's stages (policy_interface.hpp, "stages"), in
  /// the hello's order.
  struct Staged {
    Answer answer;
    std::vector<OutputValue> stages;
  };
  /// Each (observation, noise) asked with "stages": true, past the cache, in batched requests
  /// of up to batch_size() when the plug-in batches. InvalidArgument when its hello declares no
  /// stages; PluginError for an answer without them (plugin_protocol.hpp, policy_stages).
  std::vector<Staged> staged_answers(const std::vector<const Scene*>& observations,
                                     const std::vector<const Eigen::VectorXd*>& noises) const;

  /// A closed-loop rollout (policy_interface.hpp, "episodes"): from start_episode() on, each
  /// request carries "episode": {"index", "step"} (a new index, steps from 0) and is asked
  /// past the cache and not kept; end_episode() ends it.
  void start_episode() const;
  void end_episode() const { episode_.reset(); }

 private:
  Scene with_extras(const Scene& scene) const;
  /// The cache's key of (observation, noise), after checking both.
  std::string key(const Scene& observation, const Eigen::VectorXd& noise) const;
  /// One request; a batch of one (in the hello's encoding) when the plug-in batches.
  PluginReply exchange_one(const Scene& observation, const Eigen::VectorXd& noise) const;
  /// A policy request, with the images of the hello's cameras when it declared some.
  /// With `stages`, the request asks for the stages' values too ("stages": true).
  std::string request_body(const Scene& observation, const Eigen::VectorXd& noise,
                           NumberEncoding encoding = NumberEncoding::text,
                           bool stages = false) const;
  /// The answer of `reply` to `observation` (Answer), its lengths checked against the probe's
  /// (`where` names the request), cached under `key` unless in an episode.
  Answer remember(std::string key, PluginReply reply, const Scene& observation,
                  const std::string& where) const;

  std::vector<std::string> forced_extra_poses_, forced_scalars_;
  mutable PluginConnection connection_;
  mutable std::optional<PluginCapabilities> capabilities_;
  std::optional<Scene> probe_;  ///< use_probe()'s scene
  mutable std::unordered_map<std::string, Answer> cache_;
  /// Each output's length in the probe's answer (poses; an invariant output's numbers): it
  /// must not change.
  mutable std::vector<std::size_t> lengths_;
  mutable std::optional<EpisodeStep> episode_;
  mutable int episodes_started_ = 0;
};

/// One output of a PipePolicy whose hello names its outputs (or hands), as the checks ask it;
/// with `executed`, the closed loop's form: the first pose of output `executed` ahead of this
/// output's chunk (ClosedLoopOptions::compared_from = 1), when the two differ.
class PipeOutput final : public NoisyPolicy, public BatchPolicy {
 public:
  PipeOutput(std::shared_ptr<const PipePolicy> plugin, std::size_t output,
             std::optional<std::size_t> executed = std::nullopt);
  std::string name() const override;
  Eigen::Index noise_dimension() const override { return plugin_->noise_dimension(); }
  std::vector<RigidTransform> act(const Scene& observation,
                                  const Eigen::VectorXd& noise) const override;
  std::vector<std::vector<RigidTransform>> act_batch(
      const std::vector<const Scene*>& observations,
      const std::vector<const Eigen::VectorXd*>& noises) const override;
  std::vector<std::vector<RigidTransform>> act_batch_fresh(
      const std::vector<const Scene*>& observations,
      const std::vector<const Eigen::VectorXd*>& noises) const override;
  std::vector<std::vector<RigidTransform>> act_fresh(
      const std::vector<const Scene*>& observations,
      const std::vector<const Eigen::VectorXd*>& noises) const override {
    return act_batch_fresh(observations, noises);
  }
  bool mixed_shapes() const override { return true; }
  const PipePolicy& plugin() const { return *plugin_; }

 private:
  std::shared_ptr<const PipePolicy> plugin_;
  std::size_t output_;
  std::optional<std::size_t> executed_;
};

/// `plugin` as the checks ask it: in batched requests of its hello's size (BatchedPolicy) when it
/// answers batches, else one observation per request. Runs the handshake if it has not run.
std::shared_ptr<const NoisyPolicy> as_checked(std::shared_ptr<const PipePolicy> plugin);
/// The same for one output.
std::shared_ptr<const NoisyPolicy> as_checked(std::shared_ptr<const PipeOutput> output);

}  // namespace handcentric::props
