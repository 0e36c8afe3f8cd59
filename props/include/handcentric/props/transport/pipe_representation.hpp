#pragma once
// A representation written in any language, spoken to over a pipe (docs/AUDIT.md, "--exec"):
// a PluginConnection (plugin_connection.hpp) that speaks the protocol of plugin_protocol.hpp.
//
// The first request is a handshake: a small probe scene. A version-2 plug-in may answer it
// with a hello naming the extra poses and scalars it wants, and whether it decodes and answers
// flow requests; the probe is then asked again. Names given to the constructor (the command
// line's --extra-poses and --scalars) are sent whatever the hello says.
//
// Every way a plug-in can misbehave becomes a PluginError: the first line says what happened
// (not found, exited, not JSON, wrong id, NaN, a length that changes between scenes of one
// shape, no answer within the timeout), and, when the plug-in wrote on stderr, the last 20
// lines of it follow, indented (a Python traceback keeps its last line).
//
// Answers are cached by request, so a scene is sent once however many checks read it. Not
// thread-safe.
//
// A batching plug-in whose hello offers "encodings": ["base64"] gets its batched lines with
// the arrays encoded (plugin_protocol.hpp): the same numbers, bit for bit, in a fraction of the
// bytes and of the formatting and parsing time.
//
// It is also a BatchRepresentation (batch.hpp): a plug-in whose hello declares "batch": B gets
// the scenes of one encode_*_batch call not yet answered in batched requests of up to B scenes
// of one shape, and, after the hello, every encode request as a batched one (a single scene is
// a batch of one); decode and flow requests stay one per request. Without "batch",
// encode_*_batch asks one scene at a time, as encode_actions does. The audit wraps a batching
// plug-in in a BatchedRepresentation with CheckOptions::prefetch.
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <unordered_map>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/flow_target.hpp"
#include "handcentric/core/representation.hpp"
#include "handcentric/props/transport/batch.hpp"
#include "handcentric/props/transport/plugin_connection.hpp"
#include "handcentric/props/transport/plugin_protocol.hpp"

namespace handcentric::props {

class PipeRepresentation final : public Representation, public BatchRepresentation {
 public:
  /// Starts `command`. Throws InvalidArgument for an empty command, a timeout <= 0 or an
  /// empty or repeated name; PluginError if the process cannot be started. Nothing is sent
  /// until the first question.
  PipeRepresentation(std::string command, double timeout_seconds,
                     std::vector<std::string> extra_pose_names = {},
                     std::vector<std::string> scalar_names = {});
  ~PipeRepresentation() override;
  PipeRepresentation(const PipeRepresentation&) = delete;
  PipeRepresentation& operator=(const PipeRepresentation&) = delete;

  std::string name() const override;
  Eigen::VectorXd encode_actions(const Scene& scene) const override;
  /// Empty when the plug-in sends no observation.
  Eigen::VectorXd encode_observation(const Scene& scene) const override;
  /// Whether the plug-in declared "decode" in its hello.
  bool can_decode() const override;
  /// provides_observation().
  bool has_observation() const override { return provides_observation(); }
  /// A batched line may mix shapes (docs/AUDIT.md, "--exec"): fewer round trips.
  bool mixed_shapes() const override { return true; }
  /// The actions of each scene: cached ones from the cache, the others asked in batches of
  /// batch_size() scenes of any shapes (one at a time when the plug-in does not batch).
  std::vector<Eigen::VectorXd> encode_actions_batch(
      const std::vector<const Scene*>& scenes) const override;
  /// As encode_actions_batch (an encode request answers both).
  std::vector<Eigen::VectorXd> encode_observation_batch(
      const std::vector<const Scene*>& scenes) const override;
  /// The hello's "batch" (the most scenes per request), 0 when the plug-in does not batch.
  int batch_size() const { return capabilities().batch; }
  /// The plug-in's decode answer for T_0 alone (a scene with history {T_0} and no points).
  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd& actions,
                                             const RigidTransform& world_T_hand0) const override;
  /// The plug-in's decode answer. Throws InvalidArgument when it does not decode.
  std::vector<RigidTransform> decode_in_scene(const Eigen::VectorXd& actions,
                                              const Scene& observation) const override;

  /// The scene of the handshake's first request instead of the built-in probe (the hand at the
  /// origin): an audit on recorded observations sends their first, so that the plug-in meets
  /// the parts it will be sent (held arrays, extra poses) from its first request on. Call it
  /// before the handshake runs.
  void use_probe(Scene probe) { probe_ = std::move(probe); }

  /// The handshake's result (runs it if it has not run): protocol, names, decode, flow.
  const PluginCapabilities& capabilities() const;
  /// Whether the plug-in sent an "observation" (runs the handshake if it has not run).
  bool provides_observation() const;
  /// Its own flow for (scene, eps, t): {flow_input, flow_target}. Throws InvalidArgument when
  /// the plug-in did not declare "flow".
  FlowSample flow(const Scene& scene, const Eigen::VectorXd& eps, double t) const;

  /// Requests actually sent (cache misses).
  int requests_sent() const { return connection_.requests_sent(); }
  /// Seconds spent exchanging requests sent, and the part spent waiting for the plug-in's
  /// answer (plugin_connection.hpp): their difference is the pipe's overhead.
  double seconds_asking() const { return connection_.seconds_asking(); }
  double seconds_waiting() const { return connection_.seconds_waiting(); }

 private:
  /// A decode or flow request (single lines, text), cached by its body.
  const PluginReply& ask(const Scene& scene, RequestKind kind, const std::string& body) const;
  /// One encode request for `scene`; a batch of one (in the hello's encoding) when the plug-in
  /// batches.
  PluginReply exchange_one(RequestKind kind, const Scene& scene) const;
  /// The cache's key of an encode request for `scene`.
  static std::string encode_key(const Scene& scene);
  const PluginReply& remember(std::string key, PluginReply reply) const;
  std::vector<Eigen::VectorXd> encode_batch(const std::vector<const Scene*>& scenes,
                                            bool actions) const;
  const PluginReply& encoded(const Scene& scene) const;
  /// `where`: the request ("request 12", "request 12 (item 3 of 256)").
  void check_lengths(const Scene& scene, const PluginReply& reply, const std::string& where) const;
  Scene with_extras(const Scene& scene) const;

  std::string command_;
  std::vector<std::string> forced_extra_poses_, forced_scalars_;
  mutable PluginConnection connection_;
  mutable std::optional<PluginCapabilities> capabilities_;
  std::optional<Scene> probe_;  ///< use_probe()'s scene
  mutable bool has_observation_ = false;
  mutable std::unordered_map<std::string, PluginReply> cache_;
  mutable std::string last_key_;                     ///< the last scene encoded, its key
  mutable const PluginReply* last_reply_ = nullptr;  ///< its answer, in cache_
  /// (H, K, #hand points, #world points) -> (actions length, observation length, has observation)
  mutable std::map<std::tuple<int, int, int, int>, std::tuple<Eigen::Index, Eigen::Index, bool>>
      lengths_;
};

/// A plug-in's own flow (declared "flow" in its hello) as a FlowTarget: eps has the length of
/// the plug-in's actions, and each (scene, eps, t) is one flow request.
class PipeFlowTarget final : public FlowTarget {
 public:
  /// Throws InvalidArgument for a null plug-in or one that did not declare "flow".
  explicit PipeFlowTarget(std::shared_ptr<const PipeRepresentation> plugin);
  std::string name() const override;
  Eigen::Index noise_dimension(const Scene& scene) const override;
  FlowSample operator()(const Scene& scene, const Eigen::VectorXd& eps, double t) const override;

 private:
  std::shared_ptr<const PipeRepresentation> plugin_;
};

/// `plugin` as the checks ask it: in batched requests of its hello's size (BatchedRepresentation)
/// when it answers batches, else one scene per request. Runs the handshake if it has not run.
std::shared_ptr<const Representation> as_checked(std::shared_ptr<const PipeRepresentation> plugin);

}  // namespace handcentric::props
