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
  // The hands after the first are drawn as extra poses "hand:<name>" (named_output.hpp); they
  // travel in the request's "history", not in its "extra_poses".
  std::vector<std::string> hand_poses;
  for (std::size_t h = 1; h < capabilities.policy.hands.size(); ++h)
    hand_poses.push_back(kHandPosePrefix + capabilities.policy.hands[h]);
  capabilities.extra_pose_names = merged_names(capabilities.extra_pose_names, hand_poses);
  capabilities.extra_pose_names = merged_names(capabilities.extra_pose_names, forced_extra_poses_);
  capabilities.scalar_names = merged_names(capabilities.scalar_names, forced_scalars_);
  if (capabilities.noise == 0) capabilities.noise = kPolicyNoise;
  capabilities_ = capabilities;
  const Scene asked = with_extras(probe);
  if (reply.hello) reply = exchange_one(asked, fixed_noise(capabilities.noise, 1));
  lengths_.clear();  // set by the probe's answer
  (void)remember({}, std::move(reply), asked, "probe");
  cache_.clear();  // the probe's answer was kept under an empty key
  return *capabilities_;
}

void PipePolicy::start_episode() const {
  capabilities();
  episode_ = EpisodeStep{episodes_started_++, 0};
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
                                     NumberEncoding encoding, bool stages) const {
  const PolicyInterface* interface = capabilities_ ? &capabilities_->policy : nullptr;
  std::string body =
      policy_request_body(observation, noise, encoding, interface, episode_ ? &*episode_ : nullptr);
  if (stages) body += ", \"stages\": true";
  if (episode_) ++episode_->step;
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
  const PolicyInterface* interface = &capabilities_->policy;
  if (capabilities_->batch == 0) {
    return connection_.exchange(RequestKind::policy, request_body(observation, noise), false,
                                interface);
  }
  const NumberEncoding encoding = capabilities_->encoding;
  return std::move(connection_
                       .exchange_batch(RequestKind::policy,
                                       {request_body(observation, noise, encoding)}, encoding,
                                       interface)
                       .front());
}

PipePolicy::Answer PipePolicy::remember(std::string key, PluginReply reply,
                                        const Scene& observation, const std::string& where) const {
  const PolicyInterface& interface = capabilities_->policy;
  Answer answer;
  std::vector<std::size_t> lengths;  // poses per output; an invariant output's numbers
  if (!interface.named()) {
    lengths.push_back(reply.chunk.size());
    answer.push_back(std::move(reply.chunk));
  } else {
    // Invariant numbers as poses at T_0 (named_output.hpp): the checks decide them as poses.
    const RigidTransform& T0 = observation.world_T_hand_history.at(0);
    for (std::size_t o = 0; o < interface.outputs.size(); ++o) {
      OutputValue& value = reply.outputs.at(o);
      const bool pose = interface.outputs[o].kind == OutputKind::pose;
      lengths.push_back(pose ? value.poses.size() : static_cast<std::size_t>(value.numbers.size()));
      answer.push_back(interface.outputs[o].kind == OutputKind::pose
                           ? std::move(value.poses)
                           : invariant_as_poses(value.numbers.data(),
                                                static_cast<std::size_t>(value.numbers.size()),
                                                T0));
    }
  }
  if (lengths_.empty()) lengths_ = lengths;  // the probe's
  for (std::size_t o = 0; o < lengths_.size() && o < lengths.size(); ++o) {
    if (lengths[o] == lengths_[o]) continue;
    const bool pose = !interface.named() || interface.outputs[o].kind == OutputKind::pose;
    const std::string what =
        interface.named() ? "output \"" + interface.outputs[o].name + "\" " : std::string();
    connection_.fail(connection_.who() + " answered policy " + where + " with " + what +
                     std::to_string(lengths[o]) + (pose ? " poses" : " numbers") + " after " +
                     std::to_string(lengths_[o]) +
                     " for the probe; an output's length (the chunk length K) must not change");
  }
  if (episode_) return answer;                 // a step of a stateful rollout is no answer to keep
  if (cache_.size() > 200000) cache_.clear();  // bounded memory over long audits
  return cache_.insert_or_assign(std::move(key), std::move(answer)).first->second;
}

std::vector<RigidTransform> PipePolicy::act(const Scene& observation,
                                            const Eigen::VectorXd& noise) const {
  return act_batch({&observation}, {&noise}).front();
}

std::vector<std::vector<RigidTransform>> PipePolicy::act_batch(
    const std::vector<const Scene*>& observations,
    const std::vector<const Eigen::VectorXd*>& noises) const {
  return chunks(observations, noises, false);
}

std::vector<std::vector<RigidTransform>> PipePolicy::chunks(
    const std::vector<const Scene*>& observations,
    const std::vector<const Eigen::VectorXd*>& noises, bool fresh, std::size_t output,
    std::optional<std::size_t> executed) const {
  std::vector<std::vector<RigidTransform>> out;
  for (Answer& answer : answers(observations, noises, fresh)) {
    if (!executed || *executed == output) {
      out.push_back(std::move(answer.at(output)));
      continue;
    }
    // The executed pose first, then the compared chunk (closed_loop.hpp, compared_from).
    std::vector<RigidTransform> chunk{answer.at(*executed).at(0)};
    chunk.insert(chunk.end(), answer.at(output).begin(), answer.at(output).end());
    out.push_back(std::move(chunk));
  }
  return out;
}

std::vector<PipePolicy::Answer> PipePolicy::answers(
    const std::vector<const Scene*>& observations,
    const std::vector<const Eigen::VectorXd*>& noises, bool fresh) const {
  if (observations.size() != noises.size()) {
    throw InvalidArgument(name() + ": act_batch needs one noise vector per observation, got " +
                          std::to_string(noises.size()) + " for " +
                          std::to_string(observations.size()));
  }
  const int batch = batch_size();  // runs the handshake
  fresh = fresh || episode_.has_value();
  std::vector<Answer> out(observations.size());
  if (batch == 0) {  // one request per observation
    for (std::size_t i = 0; i < observations.size(); ++i) {
      std::string request = key(*observations[i], *noises[i]);
      if (const auto hit = cache_.find(request); hit != cache_.end() && !fresh) {
        out[i] = hit->second;
        continue;
      }
      PluginReply reply = exchange_one(*observations[i], *noises[i]);
      out[i] = remember(std::move(request), std::move(reply), *observations[i],
                        "request " + std::to_string(connection_.last_id()));
    }
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
    if (const auto hit = cache_.find(request); hit != cache_.end() && !fresh) {
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
        connection_.exchange_batch(RequestKind::policy, bodies, encoding, &capabilities_->policy);
    const std::string id = std::to_string(connection_.last_id());
    for (std::size_t j = from; j < to; ++j) {
      Missing& m = missing[order[j]];
      const Answer answer =
          remember(std::move(m.key), std::move(replies[j - from]), *observations[m.first],
                   "request " + id + " (item " + std::to_string(j - from) + " of " +
                       std::to_string(to - from) + ")");
      for (std::size_t i : m.at) out[i] = answer;
    }
  }
  return out;
}

std::vector<std::vector<RigidTransform>> PipePolicy::act_fresh(
    const std::vector<const Scene*>& observations,
    const std::vector<const Eigen::VectorXd*>& noises) const {
  return chunks(observations, noises, true);
}

std::vector<PipePolicy::Staged> PipePolicy::staged_answers(
    const std::vector<const Scene*>& observations,
    const std::vector<const Eigen::VectorXd*>& noises) const {
  const PluginCapabilities& declared = capabilities();  // runs the handshake
  if (declared.policy.stages.empty()) {
    throw InvalidArgument(name() +
                          ": its hello declares no \"stages\"; declare them "
                          "(docs/AUDIT.md, \"Localizing a break\")");
  }
  if (observations.size() != noises.size())
    throw InvalidArgument(name() + ": staged_answers needs one noise vector per observation");
  const std::size_t per_line = static_cast<std::size_t>(std::max(1, declared.batch));
  std::vector<Staged> out;
  for (std::size_t from = 0; from < observations.size(); from += per_line) {
    const std::size_t to = std::min(observations.size(), from + per_line);
    std::vector<PluginReply> replies;
    if (declared.batch == 0) {
      const Scene& observation = *observations[from];
      replies.push_back(
          connection_.exchange(RequestKind::policy_stages,
                               request_body(observation, *noises[from], NumberEncoding::text, true),
                               false, &declared.policy));
    } else {
      std::vector<std::string> bodies;
      for (std::size_t i = from; i < to; ++i)
        bodies.push_back(request_body(*observations[i], *noises[i], declared.encoding, true));
      replies = connection_.exchange_batch(RequestKind::policy_stages, bodies, declared.encoding,
                                           &declared.policy);
    }
    const std::string id = std::to_string(connection_.last_id());
    for (std::size_t i = from; i < to; ++i) {
      PluginReply& reply = replies[i - from];
      std::vector<OutputValue> stages = std::move(reply.stages);
      Answer answer = remember(key(*observations[i], *noises[i]), std::move(reply),
                               *observations[i], "request " + id);
      out.push_back({std::move(answer), std::move(stages)});
    }
  }
  return out;
}

std::shared_ptr<const NoisyPolicy> as_checked(std::shared_ptr<const PipePolicy> plugin) {
  const int batch = plugin->capabilities().batch;
  if (batch > 0) return std::make_shared<BatchedPolicy>(plugin, batch);
  return plugin;
}

PipeOutput::PipeOutput(std::shared_ptr<const PipePolicy> plugin, std::size_t output,
                       std::optional<std::size_t> executed)
    : plugin_(std::move(plugin)), output_(output), executed_(executed) {
  const std::size_t count = std::max<std::size_t>(1, plugin_->capabilities().policy.outputs.size());
  if (output_ >= count || (executed_ && *executed_ >= count))
    throw InvalidArgument(plugin_->name() + " has " + std::to_string(count) + " outputs");
}

std::string PipeOutput::name() const {
  const auto& outputs = plugin_->capabilities().policy.outputs;
  return outputs.empty() ? plugin_->name()
                         : plugin_->name() + ", output '" + outputs[output_].name + "'";
}

std::vector<RigidTransform> PipeOutput::act(const Scene& observation,
                                            const Eigen::VectorXd& noise) const {
  return act_batch({&observation}, {&noise}).front();
}

std::vector<std::vector<RigidTransform>> PipeOutput::act_batch(
    const std::vector<const Scene*>& observations,
    const std::vector<const Eigen::VectorXd*>& noises) const {
  return plugin_->chunks(observations, noises, false, output_, executed_);
}

std::vector<std::vector<RigidTransform>> PipeOutput::act_batch_fresh(
    const std::vector<const Scene*>& observations,
    const std::vector<const Eigen::VectorXd*>& noises) const {
  return plugin_->chunks(observations, noises, true, output_, executed_);
}

std::shared_ptr<const NoisyPolicy> as_checked(std::shared_ptr<const PipeOutput> output) {
  const int batch = output->plugin().capabilities().batch;
  if (batch > 0) return std::make_shared<BatchedPolicy>(output, batch);
  return output;
}

}  // namespace handcentric::props
