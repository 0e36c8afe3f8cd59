#include "handcentric/props/transport/pipe_representation.hpp"

#include <algorithm>

#include "handcentric/core/format.hpp"

namespace handcentric::props {

PipeRepresentation::PipeRepresentation(std::string command, double timeout_seconds,
                                       std::vector<std::string> extra_pose_names,
                                       std::vector<std::string> scalar_names)
    : command_(std::move(command)),
      forced_extra_poses_(std::move(extra_pose_names)),
      forced_scalars_(std::move(scalar_names)),
      connection_(command_, timeout_seconds) {
  require_distinct_names(forced_extra_poses_, "--extra-poses");
  require_distinct_names(forced_scalars_, "--scalars");
}

PipeRepresentation::~PipeRepresentation() = default;

std::string PipeRepresentation::name() const {
  return "exec: " + command_;
}

void PipeRepresentation::check_lengths(const Scene& scene, const PluginReply& reply,
                                       const std::string& where) const {
  const auto shape = std::make_tuple(scene.history_length(), scene.chunk_length(),
                                     static_cast<int>(scene.hand_points.size()),
                                     static_cast<int>(scene.world_points.size()));
  const auto lengths =
      std::make_tuple(reply.actions.size(), reply.observation.size(), reply.has_observation);
  const auto [known, inserted] = lengths_.emplace(shape, lengths);
  if (!inserted && known->second != lengths) {
    connection_.fail("plug-in '" + command_ +
                     "' changed its vector lengths between scenes of the same shape (H = " +
                     std::to_string(std::get<0>(shape)) +
                     ", K = " + std::to_string(std::get<1>(shape)) + ", " +
                     std::to_string(std::get<2>(shape)) + " eye-in-hand and " +
                     std::to_string(std::get<3>(shape)) + " world points): actions " +
                     std::to_string(std::get<0>(known->second)) + " then " +
                     std::to_string(reply.actions.size()) + " numbers, observation " +
                     std::to_string(std::get<1>(known->second)) + " then " +
                     std::to_string(reply.observation.size()) + " (" + where +
                     "); a length may depend on the scene's shape only");
  }
}

Scene PipeRepresentation::with_extras(const Scene& scene) const {
  if (capabilities_)
    return with_named_extras(scene, capabilities_->extra_pose_names, capabilities_->scalar_names);
  return with_named_extras(scene, forced_extra_poses_, forced_scalars_);
}

const PluginCapabilities& PipeRepresentation::capabilities() const {
  if (capabilities_) return *capabilities_;
  // The probe: the hand at the origin, one pose 10 cm ahead (or use_probe()'s scene).
  Scene probe;
  probe.world_T_hand_history = {RigidTransform::identity()};
  probe.world_T_hand_chunk = {RigidTransform::from_translation(Eigen::Vector3d(0.1, 0.0, 0.0))};
  if (probe_) probe = *probe_;
  Scene asked = with_extras(probe);
  // Before the hello the plug-in's encodings are unknown: the probe is text.
  PluginReply reply =
      connection_.exchange(RequestKind::encode, encode_request_body(asked), /*hello_allowed=*/true);
  PluginCapabilities capabilities;
  if (reply.hello) capabilities = *reply.hello;
  capabilities.extra_pose_names = merged_names(capabilities.extra_pose_names, forced_extra_poses_);
  capabilities.scalar_names = merged_names(capabilities.scalar_names, forced_scalars_);
  capabilities_ = capabilities;
  if (reply.hello) {
    asked = with_extras(probe);
    reply = exchange_one(RequestKind::encode, asked);
  }
  check_lengths(asked, reply, "request " + std::to_string(connection_.last_id()));
  has_observation_ = reply.has_observation;
  cache_.emplace(encode_key(asked), reply);
  return *capabilities_;
}

std::string PipeRepresentation::encode_key(const Scene& scene) {
  std::string key(1, 'e');
  key += scene_key(scene);
  return key;
}

const PluginReply& PipeRepresentation::encoded(const Scene& scene) const {
  // A flow evaluates the same scene once per noise vector (n + 3 times in an exact check), each
  // time asking for its actions and observation: remember the last scene's answer.
  std::string key = encode_key(scene);
  if (last_reply_ != nullptr && key == last_key_) return *last_reply_;
  capabilities();
  const PluginReply* reply = nullptr;
  if (const auto hit = cache_.find(key); hit != cache_.end()) {
    reply = &hit->second;
  } else {
    PluginReply fresh = exchange_one(RequestKind::encode, scene);
    check_lengths(scene, fresh, "request " + std::to_string(connection_.last_id()));
    reply = &remember(key, std::move(fresh));
  }
  last_key_ = std::move(key);
  last_reply_ = reply;
  return *reply;
}

const PluginReply& PipeRepresentation::ask(const Scene& scene, RequestKind kind,
                                           const std::string& body) const {
  std::string key(1, kind == RequestKind::flow ? 'f' : 'd');
  key += body;
  if (const auto hit = cache_.find(key); hit != cache_.end()) return hit->second;
  capabilities();
  PluginReply reply = connection_.exchange(kind, body, false);
  if (kind != RequestKind::decode)
    check_lengths(scene, reply, "request " + std::to_string(connection_.last_id()));
  return remember(std::move(key), std::move(reply));
}

PluginReply PipeRepresentation::exchange_one(RequestKind kind, const Scene& scene) const {
  if (capabilities_->batch == 0)
    return connection_.exchange(kind, encode_request_body(scene), false);
  const NumberEncoding encoding = capabilities_->encoding;
  return std::move(
      connection_
          .exchange_batch(kind, {encode_request_body(scene, std::nullopt, encoding)}, encoding)
          .front());
}

const PluginReply& PipeRepresentation::remember(std::string key, PluginReply reply) const {
  if (cache_.size() > 200000) {  // bounded memory over long audits
    cache_.clear();
    last_reply_ = nullptr;
  }
  return cache_.insert_or_assign(std::move(key), std::move(reply)).first->second;
}

std::vector<Eigen::VectorXd> PipeRepresentation::encode_batch(
    const std::vector<const Scene*>& scenes, bool actions) const {
  const int batch = batch_size();  // runs the handshake
  std::vector<Eigen::VectorXd> out(scenes.size());
  auto answer = [actions](const PluginReply& reply) {
    return actions ? reply.actions : reply.observation;
  };
  if (batch == 0) {  // one request per scene, as encode_actions asks
    for (std::size_t i = 0; i < scenes.size(); ++i) {
      scenes[i]->validate_observation();
      out[i] = answer(encoded(*scenes[i]));
    }
    return out;
  }
  // The scenes not cached, each once, in the order they come: a batched line may mix
  // shapes (the plug-in's helper calls its function once per shape).
  struct Missing {
    std::string key;
    const Scene* scene;
    std::vector<std::size_t> at;  // indices into `scenes`
  };
  std::vector<Missing> missing;
  std::unordered_map<std::string, std::size_t> missing_index;
  std::vector<std::size_t> order;  // indices into `missing`
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const Scene& scene = *scenes[i];
    scene.validate_observation();
    std::string key = encode_key(scene);
    if (const auto hit = cache_.find(key); hit != cache_.end()) {
      out[i] = answer(hit->second);
      continue;
    }
    const auto [at, inserted] = missing_index.try_emplace(key, missing.size());
    if (inserted) {
      order.push_back(missing.size());
      missing.push_back({std::move(key), &scene, {}});
    }
    missing[at->second].at.push_back(i);
  }
  const NumberEncoding encoding = capabilities_->encoding;
  for (std::size_t from = 0; from < order.size(); from += static_cast<std::size_t>(batch)) {
    const std::size_t to = std::min(order.size(), from + static_cast<std::size_t>(batch));
    std::vector<std::string> bodies;
    for (std::size_t j = from; j < to; ++j)
      bodies.push_back(encode_request_body(*missing[order[j]].scene, std::nullopt, encoding));
    std::vector<PluginReply> replies =
        connection_.exchange_batch(RequestKind::encode, bodies, encoding);
    const std::string id = std::to_string(connection_.last_id());
    for (std::size_t j = from; j < to; ++j) {
      Missing& m = missing[order[j]];
      PluginReply& reply = replies[j - from];
      check_lengths(*m.scene, reply,
                    "request " + id + " (item " + std::to_string(j - from) + " of " +
                        std::to_string(to - from) + ")");
      for (std::size_t i : m.at) out[i] = answer(reply);
      remember(std::move(m.key), std::move(reply));
    }
  }
  return out;
}

std::vector<Eigen::VectorXd> PipeRepresentation::encode_actions_batch(
    const std::vector<const Scene*>& scenes) const {
  for (const Scene* scene : scenes) scene->validate();
  return encode_batch(scenes, true);
}

std::vector<Eigen::VectorXd> PipeRepresentation::encode_observation_batch(
    const std::vector<const Scene*>& scenes) const {
  return encode_batch(scenes, false);
}

Eigen::VectorXd PipeRepresentation::encode_actions(const Scene& scene) const {
  scene.validate_observation();
  return encoded(scene).actions;
}

Eigen::VectorXd PipeRepresentation::encode_observation(const Scene& scene) const {
  scene.validate_observation();
  return encoded(scene).observation;
}

bool PipeRepresentation::can_decode() const {
  return capabilities().decode;
}

bool PipeRepresentation::provides_observation() const {
  capabilities();
  return has_observation_;
}

std::vector<RigidTransform> PipeRepresentation::decode_actions(
    const Eigen::VectorXd& actions, const RigidTransform& world_T_hand0) const {
  Scene observation;
  observation.world_T_hand_history = {world_T_hand0};
  return decode_in_scene(actions, with_extras(observation));
}

std::vector<RigidTransform> PipeRepresentation::decode_in_scene(const Eigen::VectorXd& actions,
                                                                const Scene& observation) const {
  if (!can_decode()) {
    throw InvalidArgument(
        "representation '" + name() +
        "' is a plug-in that did not declare \"decode\" in a hello: it encodes only");
  }
  observation.validate_observation();
  // The extras the plug-in reads (a caller's bare observation, e.g. BatchedRepresentation's
  // decode_actions, has none).
  const Scene asked = with_extras(observation);
  return ask(asked, RequestKind::decode, decode_request_body(actions, asked)).chunk;
}

FlowSample PipeRepresentation::flow(const Scene& scene, const Eigen::VectorXd& eps,
                                    double t) const {
  if (!capabilities().flow) {
    throw InvalidArgument("representation '" + name() +
                          "' did not declare \"flow\" in a hello: it has no flow of its own");
  }
  scene.validate_observation();
  const PluginReply& reply =
      ask(scene, RequestKind::flow, encode_request_body(scene, FlowQuery{&eps, t}));
  return {reply.flow_input, reply.flow_target};
}

PipeFlowTarget::PipeFlowTarget(std::shared_ptr<const PipeRepresentation> plugin)
    : plugin_(std::move(plugin)) {
  if (!plugin_) throw InvalidArgument("PipeFlowTarget needs a plug-in, got null");
  if (!plugin_->capabilities().flow) {
    throw InvalidArgument("plug-in '" + plugin_->name() + "' did not declare \"flow\" in a hello");
  }
}

std::string PipeFlowTarget::name() const {
  return plugin_->name() + " (its own flow)";
}

Eigen::Index PipeFlowTarget::noise_dimension(const Scene& scene) const {
  return plugin_->encode_actions(scene).size();
}

FlowSample PipeFlowTarget::operator()(const Scene& scene, const Eigen::VectorXd& eps,
                                      double t) const {
  if (eps.size() != noise_dimension(scene) || !eps.allFinite() || !(t >= 0.0 && t <= 1.0)) {
    throw InvalidArgument(name() + ": eps must have the length of the actions (" +
                          std::to_string(noise_dimension(scene)) +
                          ") and be finite, and t in [0, 1]; got length " +
                          std::to_string(eps.size()) + ", t = " + format_number(t));
  }
  return plugin_->flow(scene, eps, t);
}

std::shared_ptr<const Representation> as_checked(std::shared_ptr<const PipeRepresentation> plugin) {
  const int batch = plugin->capabilities().batch;
  if (batch > 0) return std::make_shared<BatchedRepresentation>(plugin, batch);
  return plugin;
}

}  // namespace handcentric::props
