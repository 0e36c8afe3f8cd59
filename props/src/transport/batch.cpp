#include "handcentric/props/transport/batch.hpp"

#include <algorithm>
#include <map>

#include "handcentric/core/errors.hpp"

namespace handcentric::props {
namespace {

void require_batch_size(int batch_size) {
  if (batch_size < 1 || batch_size > kMaxBatchSize) {
    throw InvalidArgument("batch_size=" + std::to_string(batch_size) + " is outside [1, " +
                          std::to_string(kMaxBatchSize) +
                          "]; 32 to 1024 suits a network on a CPU or GPU");
  }
}

// The pending inputs in groups of one shape and at most batch_size each, in the order they were
// recorded within a shape (so the batches, and the order of the callable's calls, are the same
// on every run).
template <class Pending, class ShapeOf>
std::vector<std::vector<const Pending*>> batches_of(const std::vector<Pending>& pending,
                                                    int batch_size, const ShapeOf& shape_of) {
  std::map<std::string, std::vector<const Pending*>> by_shape;
  std::vector<std::string> order;
  for (const Pending& p : pending) {
    const std::string shape = shape_of(p);
    auto [at, inserted] = by_shape.try_emplace(shape);
    if (inserted) order.push_back(shape);
    at->second.push_back(&p);
  }
  std::vector<std::vector<const Pending*>> out;
  const auto size = static_cast<std::size_t>(batch_size);
  for (const std::string& shape : order) {
    const std::vector<const Pending*>& all = by_shape[shape];
    for (std::size_t from = 0; from < all.size(); from += size) {
      out.emplace_back(
          all.begin() + static_cast<std::ptrdiff_t>(from),
          all.begin() + static_cast<std::ptrdiff_t>(std::min(all.size(), from + size)));
    }
  }
  return out;
}

}  // namespace

std::vector<RigidTransform> BatchRepresentation::decode_in_scene(const Eigen::VectorXd&,
                                                                 const Scene&) const {
  throw InvalidArgument(name() + " has no decode function");
}

// ---------------------------------------------------------------------------------------------
// BatchedPolicy

BatchedPolicy::BatchedPolicy(std::shared_ptr<const BatchPolicy> policy, int batch_size)
    : policy_(std::move(policy)), batch_size_(batch_size) {
  if (!policy_) throw InvalidArgument("BatchedPolicy needs a policy, got null");
  require_batch_size(batch_size);
  noise_dimension_ = policy_->noise_dimension();
}

std::vector<RigidTransform> BatchedPolicy::act(const Scene& observation,
                                               const Eigen::VectorXd& noise) const {
  observation.validate_observation();
  std::string key = detail::scene_key(observation, false);
  key.append(reinterpret_cast<const char*>(noise.data()),
             sizeof(double) * static_cast<std::size_t>(noise.size()));
  if (const auto* hit = cache_.find(key)) return *hit;
  // An input that failed in a batch is asked alone, where it fails again inside its case, so
  // that the error names that case (check.cpp).
  if (prefetching() && !failing_.count(key)) {
    if (pending_keys_.emplace(key, true).second) {
      pending_.push_back({observation, noise, std::move(key)});
      detail::enlist(const_cast<BatchedPolicy&>(*this));
    }
    throw PendingEvaluation{};
  }
  const Pending one{observation, noise, key};
  evaluate({&one});
  return *cache_.find(key);
}

std::vector<std::vector<RigidTransform>> BatchedPolicy::counted_act_batch(
    const std::vector<const Scene*>& observations,
    const std::vector<const Eigen::VectorXd*>& noises, bool fresh) const {
  std::vector<std::vector<RigidTransform>> chunks =
      fresh ? policy_->act_batch_fresh(observations, noises)
            : policy_->act_batch(observations, noises);
  ++batches_;
  evaluations_ += observations.size();
  if (chunks.size() != observations.size()) {
    throw InvalidArgument("policy " + name() + " returned " + std::to_string(chunks.size()) +
                          " chunks for a batch of " + std::to_string(observations.size()) +
                          " observations; it must return one chunk per observation");
  }
  return chunks;
}

void BatchedPolicy::evaluate(const std::vector<const Pending*>& inputs) const {
  std::vector<const Scene*> observations;
  std::vector<const Eigen::VectorXd*> noises;
  for (const Pending* p : inputs) {
    observations.push_back(&p->observation);
    noises.push_back(&p->noise);
  }
  std::vector<std::vector<RigidTransform>> chunks = counted_act_batch(observations, noises);
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    if (chunk_length_ == 0) chunk_length_ = chunks[i].size();
    if (chunks[i].size() != chunk_length_) {
      throw InvalidArgument("policy " + name() + " returned " + std::to_string(chunks[i].size()) +
                            " poses after " + std::to_string(chunk_length_) +
                            " earlier; the chunk length K must not change");
    }
    cache_.put(inputs[i]->key, std::move(chunks[i]));
  }
}

std::vector<std::vector<RigidTransform>> BatchedPolicy::act_fresh(
    const std::vector<const Scene*>& observations,
    const std::vector<const Eigen::VectorXd*>& noises) const {
  std::vector<std::vector<RigidTransform>> out;
  policy_->watch_draws(true);
  try {
    const auto size = static_cast<std::size_t>(batch_size_);
    for (std::size_t at = 0; at < observations.size(); at += size) {
      const std::size_t end = std::min(observations.size(), at + size);
      const std::vector<const Scene*> rows(observations.begin() + at, observations.begin() + end);
      const std::vector<const Eigen::VectorXd*> row_noises(noises.begin() + at,
                                                           noises.begin() + end);
      for (auto& chunk : counted_act_batch(rows, row_noises, true)) out.push_back(std::move(chunk));
    }
  } catch (...) {
    policy_->watch_draws(false);
    throw;
  }
  policy_->watch_draws(false);
  return out;
}

std::size_t BatchedPolicy::flush() {
  std::vector<Pending> pending;
  pending.swap(pending_);
  pending_keys_.clear();
  const bool mixed = policy_->mixed_shapes();
  const auto batches = batches_of(pending, batch_size_, [mixed](const Pending& p) {
    return mixed ? std::string() : detail::shape_key(p.observation, false);
  });
  for (const auto& batch : batches) {
    try {
      evaluate(batch);
    } catch (const InvalidArgument&) {
      // One of its inputs got an answer that cannot be read (NaN, a wrong shape or type, not a
      // pose): find the first such one alone (the inputs before it are answered and cached,
      // those after it asked again in the next pass). Other errors (a Python exception, Ctrl-C,
      // a plug-in that stopped) stop the audit at once, as before.
      for (const Pending* input : batch) {
        try {
          evaluate({input});
        } catch (const InvalidArgument&) {
          failing_.insert(input->key);
          break;
        }
      }
    }
  }
  return pending.size();
}

// ---------------------------------------------------------------------------------------------
// BatchedRepresentation

BatchedRepresentation::BatchedRepresentation(
    std::shared_ptr<const BatchRepresentation> representation, int batch_size)
    : representation_(std::move(representation)), batch_size_(batch_size) {
  if (!representation_) throw InvalidArgument("BatchedRepresentation needs a representation");
  require_batch_size(batch_size);
  observation_.with_chunk = false;
}

Eigen::VectorXd BatchedRepresentation::encode_actions(const Scene& scene) const {
  scene.validate();
  return encode(actions_, scene);
}

Eigen::VectorXd BatchedRepresentation::encode_observation(const Scene& scene) const {
  if (!has_observation()) return {};
  scene.validate_observation();
  return encode(observation_, scene);
}

Eigen::VectorXd BatchedRepresentation::encode(const Side& side, const Scene& scene) const {
  std::string key = detail::scene_key(scene, side.with_chunk);
  if (const auto* hit = side.cache.find(key)) return *hit;
  if (prefetching()) {
    if (side.pending_keys.emplace(key, true).second) {
      side.pending.push_back({scene, std::move(key)});
      detail::enlist(const_cast<BatchedRepresentation&>(*this));
    }
    throw PendingEvaluation{};
  }
  const Pending one{scene, key};
  evaluate(side, {&one});
  return *side.cache.find(key);
}

void BatchedRepresentation::evaluate(const Side& side,
                                     const std::vector<const Pending*>& inputs) const {
  std::vector<const Scene*> scenes;
  for (const Pending* p : inputs) scenes.push_back(&p->scene);
  std::vector<Eigen::VectorXd> out = side.with_chunk
                                         ? representation_->encode_actions_batch(scenes)
                                         : representation_->encode_observation_batch(scenes);
  ++batches_;
  evaluations_ += inputs.size();
  if (out.size() != inputs.size()) {
    throw InvalidArgument(name() + " returned " + std::to_string(out.size()) + " " +
                          (side.with_chunk ? "action" : "observation") +
                          " vectors for a batch of " + std::to_string(inputs.size()) +
                          " scenes; it must return one per scene");
  }
  for (std::size_t i = 0; i < inputs.size(); ++i) side.cache.put(inputs[i]->key, std::move(out[i]));
}

std::size_t BatchedRepresentation::flush(Side& side) {
  std::vector<Pending> pending;
  pending.swap(side.pending);
  side.pending_keys.clear();
  const bool with_chunk = side.with_chunk, mixed = representation_->mixed_shapes();
  const auto batches = batches_of(pending, batch_size_, [with_chunk, mixed](const Pending& p) {
    return mixed ? std::string() : detail::shape_key(p.scene, with_chunk);
  });
  for (const auto& batch : batches) evaluate(side, batch);
  return pending.size();
}

std::size_t BatchedRepresentation::flush() {
  return flush(actions_) + flush(observation_);
}

std::vector<RigidTransform> BatchedRepresentation::decode_actions(
    const Eigen::VectorXd& actions, const RigidTransform& world_T_hand0) const {
  Scene observation;
  observation.world_T_hand_history = {world_T_hand0};
  return decode_in_scene(actions, observation);
}

std::vector<RigidTransform> BatchedRepresentation::decode_in_scene(const Eigen::VectorXd& actions,
                                                                   const Scene& observation) const {
  std::string key = detail::scene_key(observation, false);
  key.append(reinterpret_cast<const char*>(actions.data()),
             sizeof(double) * static_cast<std::size_t>(actions.size()));
  if (const auto* hit = decoded_.find(key)) return *hit;
  return decoded_.put(std::move(key), representation_->decode_in_scene(actions, observation));
}

}  // namespace handcentric::props
