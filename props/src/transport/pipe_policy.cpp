#include "handcentric/props/transport/pipe_policy.hpp"

#include <algorithm>

#include "../wire_arrays.hpp"

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
  // The probe: the hand at the origin (or use_probe()'s scene), the default noise.
  Scene probe;
  probe.world_T_hand_history = {RigidTransform::identity()};
  if (probe_) probe = *probe_;
  const Eigen::VectorXd noise = fixed_noise(kPolicyNoise, 1);
  PluginReply reply = connection_.exchange(RequestKind::policy,
                                           policy_request_body(with_extras(probe), noise), true);
  PluginCapabilities capabilities;
  if (reply.hello) capabilities = *reply.hello;
  capabilities.extra_pose_names = merged_names(capabilities.extra_pose_names, forced_extra_poses_);
  capabilities.scalar_names = merged_names(capabilities.scalar_names, forced_scalars_);
  if (capabilities.noise == 0) capabilities.noise = kPolicyNoise;
  capabilities_ = capabilities;
  if (reply.hello) reply = exchange_one(with_extras(probe), fixed_noise(capabilities.noise, 1));
  chunk_length_ = reply.chunk.size();
  return *capabilities_;
}

Eigen::Index PipePolicy::noise_dimension() const {
  return capabilities().noise;
}

std::string PipePolicy::key(const Scene& observation, const Eigen::VectorXd& noise) const {
  observation.validate_observation();
  if (noise.size() != noise_dimension()) {
    throw InvalidArgument(name() + " reads " + std::to_string(noise_dimension()) +
                          " noise numbers, got " + std::to_string(noise.size()));
  }
  std::string out = scene_key(observation, /*with_chunk=*/false);  // a request has no chunk
  out.append(reinterpret_cast<const char*>(noise.data()),
             static_cast<std::size_t>(noise.size()) * sizeof(double));
  return out;
}

std::string PipePolicy::request_body(const Scene& observation, const Eigen::VectorXd& noise,
                                     NumberEncoding encoding) const {
  std::string body = policy_request_body(observation, noise, encoding);
  if (!capabilities_ || !capabilities_->cameras) return body;
  // Images always travel as base64 float32 arrays: a 64 x 48 RGB-D image is 49 KB so, ~150 KB
  // as JSON numbers.
  const CameraRig& rig = *capabilities_->cameras;
  const std::vector<CameraImage> images = render_views(observation, rig);
  body += ", \"images\": {";
  for (std::size_t v = 0; v < images.size(); ++v) {
    const std::vector<float> pixels = network_image(images[v], rig.channels);
    body += (v > 0 ? ", \"" : "\"") + to_string(rig.views[v]) + "\": ";
    wire::append_float32_array(
        body,
        {static_cast<std::size_t>(channel_count(rig.channels)),
         static_cast<std::size_t>(rig.camera.height), static_cast<std::size_t>(rig.camera.width)},
        pixels.data());
  }
  body += '}';
  return body;
}

PluginReply PipePolicy::exchange_one(const Scene& observation, const Eigen::VectorXd& noise) const {
  if (capabilities_->batch == 0) {
    return connection_.exchange(RequestKind::policy, request_body(observation, noise), false);
  }
  const NumberEncoding encoding = capabilities_->encoding;
  return std::move(connection_
                       .exchange_batch(RequestKind::policy,
                                       {request_body(observation, noise, encoding)}, encoding)
                       .front());
}

const std::vector<RigidTransform>& PipePolicy::remember(std::string key, PluginReply reply,
                                                        const std::string& where) const {
  if (reply.chunk.size() != chunk_length_) {
    connection_.fail(connection_.who() + " answered policy " + where + " with " +
                     std::to_string(reply.chunk.size()) + " poses after " +
                     std::to_string(chunk_length_) +
                     " for the probe; the chunk length K must not change");
  }
  if (cache_.size() > 200000) cache_.clear();  // bounded memory over long audits
  return cache_.insert_or_assign(std::move(key), std::move(reply.chunk)).first->second;
}

std::vector<RigidTransform> PipePolicy::act(const Scene& observation,
                                            const Eigen::VectorXd& noise) const {
  capabilities();
  std::string request = key(observation, noise);
  if (const auto hit = cache_.find(request); hit != cache_.end() && !past_cache_)
    return hit->second;
  PluginReply reply = exchange_one(observation, noise);
  return remember(std::move(request), std::move(reply),
                  "request " + std::to_string(connection_.last_id()));
}

std::vector<std::vector<RigidTransform>> PipePolicy::act_batch(
    const std::vector<const Scene*>& observations,
    const std::vector<const Eigen::VectorXd*>& noises) const {
  if (observations.size() != noises.size()) {
    throw InvalidArgument(name() + ": act_batch needs one noise vector per observation, got " +
                          std::to_string(noises.size()) + " for " +
                          std::to_string(observations.size()));
  }
  const int batch = batch_size();  // runs the handshake
  std::vector<std::vector<RigidTransform>> out(observations.size());
  if (batch == 0) {  // one request per observation, as act asks
    for (std::size_t i = 0; i < observations.size(); ++i)
      out[i] = act(*observations[i], *noises[i]);
    return out;
  }
  // The inputs not cached, each once, in the order they come: a batched line may mix shapes
  // (the plug-in's helper calls its function once per shape).
  struct Missing {
    std::string key;
    std::size_t first;            // the index of its first occurrence in `observations`
    std::vector<std::size_t> at;  // indices into `observations`
  };
  std::vector<Missing> missing;
  std::unordered_map<std::string, std::size_t> missing_index;
  std::vector<std::size_t> order;  // indices into `missing`
  for (std::size_t i = 0; i < observations.size(); ++i) {
    const Scene& observation = *observations[i];
    std::string request = key(observation, *noises[i]);
    if (const auto hit = cache_.find(request); hit != cache_.end() && !past_cache_) {
      out[i] = hit->second;
      continue;
    }
    const auto [at, inserted] = missing_index.try_emplace(request, missing.size());
    if (inserted) {
      order.push_back(missing.size());
      missing.push_back({std::move(request), i, {}});
    }
    missing[at->second].at.push_back(i);
  }
  for (std::size_t from = 0; from < order.size(); from += static_cast<std::size_t>(batch)) {
    const std::size_t to = std::min(order.size(), from + static_cast<std::size_t>(batch));
    std::vector<std::string> bodies;
    const NumberEncoding encoding = capabilities_->encoding;
    for (std::size_t j = from; j < to; ++j) {
      const std::size_t i = missing[order[j]].first;
      bodies.push_back(request_body(*observations[i], *noises[i], encoding));
    }
    std::vector<PluginReply> replies =
        connection_.exchange_batch(RequestKind::policy, bodies, encoding);
    const std::string id = std::to_string(connection_.last_id());
    for (std::size_t j = from; j < to; ++j) {
      Missing& m = missing[order[j]];
      const std::vector<RigidTransform>& chunk =
          remember(std::move(m.key), std::move(replies[j - from]),
                   "request " + id + " (item " + std::to_string(j - from) + " of " +
                       std::to_string(to - from) + ")");
      for (std::size_t i : m.at) out[i] = chunk;
    }
  }
  return out;
}

std::vector<std::vector<RigidTransform>> PipePolicy::act_fresh(
    const std::vector<const Scene*>& observations,
    const std::vector<const Eigen::VectorXd*>& noises) const {
  past_cache_ = true;
  try {
    auto out = act_batch(observations, noises);
    past_cache_ = false;
    return out;
  } catch (...) {
    past_cache_ = false;
    throw;
  }
}

std::shared_ptr<const NoisyPolicy> as_checked(std::shared_ptr<const PipePolicy> plugin) {
  const int batch = plugin->capabilities().batch;
  if (batch > 0) return std::make_shared<BatchedPolicy>(plugin, batch);
  return plugin;
}

}  // namespace handcentric::props
