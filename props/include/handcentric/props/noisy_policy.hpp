#pragma once
// The interface through which every part of props meets a whole policy: the checks ask it
// (policy_audit.hpp, preflight.hpp), the observation models wrap it (cameras), the transports
// implement it (a batched callable, a plug-in over the pipe). It has a header of its own so that
// none of them needs another's header to name it.
#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "handcentric/core/chunk_policy.hpp"
#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/scene.hpp"

namespace handcentric::props {

/// A policy under audit: an observation and a noise vector in, the world chunk out.
class NoisyPolicy {
 public:
  virtual ~NoisyPolicy() = default;
  virtual std::string name() const = 0;
  /// The length of the noise vector act() reads.
  virtual Eigen::Index noise_dimension() const = 0;
  /// T_1..T_K for `observation` (its history, points, extras; its chunk is ignored).
  virtual std::vector<RigidTransform> act(const Scene& observation,
                                          const Eigen::VectorXd& noise) const = 0;
  /// The chunks for (observations[i], noises[i]) asked afresh, past any cache, in ONE call when
  /// batched(): the questions of the preflight (preflight.hpp), which asks the same observation
  /// several times and compares rows across batches. Default: act() on each.
  virtual std::vector<std::vector<RigidTransform>> act_fresh(
      const std::vector<const Scene*>& observations,
      const std::vector<const Eigen::VectorXd*>& noises) const;
  /// True when act_fresh asks its observations as the rows of one batch.
  virtual bool batched() const { return false; }
  /// The global random generators the last act_fresh call drew from (e.g. "torch's CPU
  /// generator"), empty when none; nullopt when the policy cannot tell (a C++ policy, a plug-in).
  virtual std::optional<std::vector<std::string>> last_draws() const { return std::nullopt; }
};

/// A ChunkPolicy, whose noise comes from a seed, as a NoisyPolicy: the noise vector's bits are
/// hashed into the seed, so one vector gives one chunk, and different vectors independent
/// chunks. Its output is not affine in that vector, so in distribution it is decided by the
/// tests.
class SeededPolicy final : public NoisyPolicy {
 public:
  /// Throws InvalidArgument for a null policy.
  explicit SeededPolicy(std::shared_ptr<const ChunkPolicy> policy);
  std::string name() const override { return policy_->name(); }
  Eigen::Index noise_dimension() const override { return 4; }
  std::vector<RigidTransform> act(const Scene& observation,
                                  const Eigen::VectorXd& noise) const override;

 private:
  std::shared_ptr<const ChunkPolicy> policy_;
};

/// The first `n` standard normals of mt19937_64(seed) (core/sampling.hpp): the noise a policy
/// (or a flow target) is asked with in the pointwise checks.
Eigen::VectorXd fixed_noise(Eigen::Index n, std::uint64_t seed);

/// The seed of one pointwise case's noise (a policy's or a flow's: fixed_noise(n, seed)), hashed
/// (FNV-1a) from the audit's seed and the scene's bytes (its held arrays by value), and g's when
/// given: each case its own draw, o and g o sharing it, the same case the same noise in every run
/// and every check that decides it. Independent draws over the cases are what let a pointwise
/// "yes" speak for the law too (policy_audit.hpp, Method::from_pointwise); one noise for every
/// case would test one n only. Whether g counts: checks/check.hpp, pointwise_noise_seed.
std::uint64_t case_noise_seed(std::uint64_t seed, const Scene& scene,
                              const RigidTransform* g = nullptr);

}  // namespace handcentric::props
