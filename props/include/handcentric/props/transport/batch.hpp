#pragma once
// The map under audit evaluated on many inputs at once (a Python callable on stacked arrays, a
// plug-in answering many scenes per line), with verdicts the same bit for bit as one call at a
// time.
//
// How. A check's cases, and the inputs each case asks for, follow from its seed; only a case's next
// question can depend on an answer (the floor, then the map's rounding, then off the case; the
// affine probes, then the draws). So with CheckOptions::prefetch, run_check first runs prefetch
// passes over its cases: in such a pass a BatchedPolicy or BatchedRepresentation asked for an input
// it has no answer for records it and throws PendingEvaluation, which stops that case only (cases
// where several questions are known at once ask them all first: ask_ahead()). The recorded inputs
// are then evaluated together, in batches of at most batch_size inputs (of one shape unless the map
// takes mixed shapes), and the next pass goes a question further. When a pass records nothing new,
// the real pass runs: it asks the same questions in the same order as an unbatched check and finds
// every answer cached, so its verdict, witness and JSON are those of the unbatched check, bit for
// bit, provided the map's answer for one input does not depend on the other inputs of its batch.
// The prefetch passes may ask for inputs the real pass never reaches (cases after the first
// failure); shrinking a failure asks one input at a time.
#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "handcentric/core/representation.hpp"
#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/scene.hpp"
#include "handcentric/props/noisy_policy.hpp"
#include "handcentric/props/prefetch.hpp"
#include "handcentric/props/scene_key.hpp"

namespace handcentric::props {

/// The largest batch_size a batched map takes (one batch of a policy holds batch_size noise
/// vectors, up to kMaxPolicyNoise numbers each).
inline constexpr int kMaxBatchSize = 1 << 16;

/// A policy that answers many observations at once (a Python callable on stacked arrays, a
/// plug-in over the pipe).
class BatchPolicy {
 public:
  virtual ~BatchPolicy() = default;
  virtual std::string name() const = 0;
  virtual Eigen::Index noise_dimension() const = 0;
  /// One world-frame chunk per (observations[i], noises[i]). Every observation has the same
  /// shape (detail::shape_key) unless mixed_shapes(); at most the BatchedPolicy's batch_size.
  virtual std::vector<std::vector<RigidTransform>> act_batch(
      const std::vector<const Scene*>& observations,
      const std::vector<const Eigen::VectorXd*>& noises) const = 0;
  /// True when act_batch takes observations of several shapes in one call (a plug-in whose
  /// helper splits them): then a batch is any batch_size inputs, in the order recorded.
  virtual bool mixed_shapes() const { return false; }
  /// act_batch past any cache the policy keeps of its own (a plug-in's): the preflight's repeated
  /// questions must reach the policy. Default: act_batch.
  virtual std::vector<std::vector<RigidTransform>> act_batch_fresh(
      const std::vector<const Scene*>& observations,
      const std::vector<const Eigen::VectorXd*>& noises) const {
    return act_batch(observations, noises);
  }
  /// As NoisyPolicy::last_draws, for the last act_batch call (a Python callable watches torch's,
  /// NumPy's and Python's global generators while watch_draws(true)).
  virtual std::optional<std::vector<std::string>> last_draws() const { return std::nullopt; }
  /// Asks the policy to record last_draws() from now on (true) or to stop (false): watching
  /// costs a copy of each generator's state per call, so only the preflight watches.
  virtual void watch_draws(bool /*on*/) const {}
};

/// A representation that encodes many scenes at once.
class BatchRepresentation {
 public:
  virtual ~BatchRepresentation() = default;
  virtual std::string name() const = 0;
  /// True when it has an observation map (else encode_observation gives empty vectors).
  virtual bool has_observation() const = 0;
  /// The action vector of each scene (each with its chunk), all of one shape unless
  /// mixed_shapes().
  virtual std::vector<Eigen::VectorXd> encode_actions_batch(
      const std::vector<const Scene*>& scenes) const = 0;
  /// The observation vector of each scene, all of one shape unless mixed_shapes().
  virtual std::vector<Eigen::VectorXd> encode_observation_batch(
      const std::vector<const Scene*>& scenes) const = 0;
  virtual bool can_decode() const { return false; }
  /// As BatchPolicy::mixed_shapes.
  virtual bool mixed_shapes() const { return false; }
  /// The world chunk that `actions` encode in `observation` (one at a time: only the
  /// injectivity round trips ask).
  virtual std::vector<RigidTransform> decode_in_scene(const Eigen::VectorXd& actions,
                                                      const Scene& observation) const;
};

/// Answers by key, bounded by entries and bytes (cleared when full: the checks ask the same
/// scenes again across groups and components, but never need everything at once).
template <class Value>
class AnswerCache {
 public:
  const Value* find(const std::string& key) const {
    const auto hit = map_.find(key);
    return hit == map_.end() ? nullptr : &hit->second;
  }
  const Value& put(std::string key, Value value) {
    if (map_.size() >= kMaxEntries || bytes_ > kMaxBytes) {
      map_.clear();
      bytes_ = 0;
    }
    bytes_ += key.size();
    return map_.insert_or_assign(std::move(key), std::move(value)).first->second;
  }

 private:
  static constexpr std::size_t kMaxEntries = 400000;
  static constexpr std::size_t kMaxBytes = std::size_t{512} << 20;
  std::unordered_map<std::string, Value> map_;
  std::size_t bytes_ = 0;
};

/// The NoisyPolicy the checks call, around a BatchPolicy: answers from its cache; asked for a
/// new input during a prefetch pass, records it (PendingEvaluation); flush() evaluates the
/// recorded inputs in batches of at most batch_size; outside a prefetch pass, a new input is
/// evaluated alone. Every chunk must have the same length (else InvalidArgument).
class BatchedPolicy final : public NoisyPolicy, public Prefetcher {
 public:
  /// Throws InvalidArgument for a null policy or batch_size outside [1, kMaxBatchSize].
  BatchedPolicy(std::shared_ptr<const BatchPolicy> policy, int batch_size);
  std::string name() const override { return policy_->name(); }
  Eigen::Index noise_dimension() const override { return noise_dimension_; }
  std::vector<RigidTransform> act(const Scene& observation,
                                  const Eigen::VectorXd& noise) const override;
  std::size_t flush() override;
  /// act_batch on the policy itself (no cache), in calls of at most batch_size; the policy
  /// records which global generators each call drew from (last_draws).
  std::vector<std::vector<RigidTransform>> act_fresh(
      const std::vector<const Scene*>& observations,
      const std::vector<const Eigen::VectorXd*>& noises) const override;
  bool batched() const override { return batch_size_ > 1; }
  std::optional<std::vector<std::string>> last_draws() const override {
    return policy_->last_draws();
  }
  /// Calls of act_batch so far, and the inputs they carried (for benchmarks and tests).
  std::size_t batches() const { return batches_; }
  std::size_t evaluations() const { return evaluations_; }

 private:
  struct Pending {
    Scene observation;
    Eigen::VectorXd noise;
    std::string key;
  };
  void evaluate(const std::vector<const Pending*>& inputs) const;
  /// policy_->act_batch (act_batch_fresh when `fresh`), counted, its number of chunks checked.
  std::vector<std::vector<RigidTransform>> counted_act_batch(
      const std::vector<const Scene*>& observations,
      const std::vector<const Eigen::VectorXd*>& noises, bool fresh = false) const;

  std::shared_ptr<const BatchPolicy> policy_;
  int batch_size_;
  Eigen::Index noise_dimension_;
  mutable AnswerCache<std::vector<RigidTransform>> cache_;
  mutable std::vector<Pending> pending_;
  mutable std::unordered_map<std::string, bool> pending_keys_;
  std::unordered_set<std::string> failing_;  ///< inputs that failed in a batch: asked alone
  mutable std::size_t chunk_length_ = 0;
  mutable std::size_t batches_ = 0, evaluations_ = 0;
};

/// The Representation the checks call, around a BatchRepresentation, as BatchedPolicy is for a
/// policy (actions and observation cached and batched separately).
class BatchedRepresentation final : public Representation, public Prefetcher {
 public:
  /// Throws InvalidArgument for a null representation or batch_size outside [1, kMaxBatchSize].
  BatchedRepresentation(std::shared_ptr<const BatchRepresentation> representation, int batch_size);
  std::string name() const override { return representation_->name(); }
  bool has_observation() const { return representation_->has_observation(); }
  Eigen::VectorXd encode_actions(const Scene& scene) const override;
  Eigen::VectorXd encode_observation(const Scene& scene) const override;
  bool can_decode() const override { return representation_->can_decode(); }
  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd& actions,
                                             const RigidTransform& world_T_hand0) const override;
  std::vector<RigidTransform> decode_in_scene(const Eigen::VectorXd& actions,
                                              const Scene& observation) const override;
  std::size_t flush() override;
  std::size_t batches() const { return batches_; }
  std::size_t evaluations() const { return evaluations_; }

 private:
  struct Pending {
    Scene scene;
    std::string key;
  };
  struct Side {  // actions or observation
    bool with_chunk = true;
    mutable AnswerCache<Eigen::VectorXd> cache;
    mutable std::vector<Pending> pending;
    mutable std::unordered_map<std::string, bool> pending_keys;
  };
  Eigen::VectorXd encode(const Side& side, const Scene& scene) const;
  void evaluate(const Side& side, const std::vector<const Pending*>& inputs) const;
  std::size_t flush(Side& side);

  std::shared_ptr<const BatchRepresentation> representation_;
  int batch_size_;
  Side actions_, observation_;
  /// Round trips already asked: a check that runs its cases in prefetch passes asks again.
  mutable AnswerCache<std::vector<RigidTransform>> decoded_;
  mutable std::size_t batches_ = 0, evaluations_ = 0;
};

}  // namespace handcentric::props
