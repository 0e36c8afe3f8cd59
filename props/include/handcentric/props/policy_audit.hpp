#pragma once
// The audit of a whole policy (eq. 4): is a(g o, n) = g a(o, n), where o is an observation,
// n the policy's noise and a(o, n) its world-frame chunk T_1..T_K? A policy can break
// equivariance in its encoder, its noise, its sampler or its decoder even when its
// representation is right, so the thing shipped is audited as a black box:
//
//   pointwise       : the same noise n for o and g o; the chunks are compared pose by pose
//                     (distance |R_a - R_b|_F + |p_a - p_b|) within REL (1 + L). Theorem 1: the
//                     outer hand-centric policy passes for any network.
//   in distribution : n ~ N(0, I) drawn independently: the law of g a(o, n) against the law of
//                     a(g o, n), each pose flattened as [p, R] (on which g acts affinely).
//                     Exactly on the coordinates affine in n on both sides (distribution.hpp),
//                     by the energy, paired mean and scale tests on the others, with what they
//                     can miss. A policy that adds isotropic noise in the world frame is
//                     equivariant in distribution under rotations, not pointwise; one that adds
//                     noise with per-axis scales in the world frame is neither.
// Both views and all groups, as for representations (classifier.hpp).
#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "handcentric/core/chunk_policy.hpp"
#include "handcentric/props/check.hpp"
#include "handcentric/props/classifier.hpp"
#include "handcentric/props/distribution.hpp"

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

/// eq. (4) pointwise: a(g o, n) = g a(o, n) with n the first noise_dimension() normals of
/// mt19937_64(options.noise_seed). The witness's before/after are g a(o) and a(g o), each pose
/// flattened to [p, r(R)].
Verdict check_policy_equivariance(const NoisyPolicy& policy, Group group,
                                  const CheckOptions& options = {});

/// eq. (4) in distribution (see the top of this file). The witness's before/after are the
/// laws' means (exact) or first samples (tests), each pose flattened to [p, R row-major].
Verdict check_policy_distribution(const NoisyPolicy& policy, Group group,
                                  const CheckOptions& options = {},
                                  const DistributionOptions& distribution = {});

/// Both modes, options.views and options.groups (component Component::policy; the verdict's
/// `invariant` means equivariant), with the float32 note of classifier.hpp.
Classification classify_policy(std::shared_ptr<const NoisyPolicy> policy,
                               const ClassifierOptions& options = {});

/// {"policies": [{"name", "summary": {view: {mode: {group: bool}}}, "checks": [{"group",
/// "mode", "view", "method", "equivariant", "max_error", "cases", "seed", "witness", ...}]}]}
std::string policy_audit_json(const std::vector<Classification>& policies);

}  // namespace handcentric::props
