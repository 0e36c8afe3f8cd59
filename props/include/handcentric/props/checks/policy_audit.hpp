#pragma once
// The audit of a whole policy (eq. 4): is a(g o, n) = g a(o, n), where o is an observation,
// n the policy's noise and a(o, n) its world-frame chunk T_1..T_K? A policy can break
// equivariance in its encoder, its noise, its sampler or its decoder even when its
// representation is right, so the thing shipped is audited as a black box:
//
//   pointwise       : the same noise n for o and g o, n drawn afresh for each case
//                     (pointwise_noise_seed); the chunks are compared pose by pose
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
//
// The law from the pointwise check (classify_policy, Method::from_pointwise): a policy that is a
// function of its inputs (the preflight) and holds pointwise on cases (o, n) drawn with
// independent noise holds in law: g a(o, N) and a(g o, N) are then one map of the same N, within
// the pointwise tolerance but on the (o, n) draws where it fails, whose share a pointwise "yes"
// bounds (detectable_frequency: below 4.6 / cases with 99% confidence). So the in-distribution
// check runs only where the pointwise check fails (isotropic world noise: NO pointwise, yes in
// law), or where the preflight did not run or found the policy's own randomness, or when asked
// (ClassifierOptions::law_from_pointwise = false). The tests would add power only against a
// violation on fewer draws than that share but large enough to move a mean.
#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "handcentric/props/checks/check.hpp"
#include "handcentric/props/checks/classifier.hpp"
#include "handcentric/props/transport/policy_interface.hpp"
#include "handcentric/props/checks/distribution.hpp"
#include "handcentric/props/noisy_policy.hpp"

namespace handcentric::props {

/// eq. (4) pointwise: a(g o, n) = g a(o, n) with n = fixed_noise(noise_dimension(),
/// pointwise_noise_seed(options, o, g)), its own draw for each case. The witness's before/after are
/// g a(o) and a(g o), each pose flattened to [p, r(R)].
Verdict check_policy_equivariance(const NoisyPolicy& policy, Group group,
                                  const CheckOptions& options = {});

/// eq. (4) in distribution (see the top of this file). The witness's before/after are the
/// laws' means (exact) or first samples (tests), each pose flattened to [p, R row-major].
Verdict check_policy_distribution(const NoisyPolicy& policy, Group group,
                                  const CheckOptions& options = {},
                                  const DistributionOptions& distribution = {});

/// Both modes, options.views and options.groups (component Component::policy; the verdict's
/// `invariant` means equivariant), with the float32 note of classifier.hpp; an in-distribution
/// verdict from the pointwise one where that holds (the top of this file).
Classification classify_policy(std::shared_ptr<const NoisyPolicy> policy,
                               const ClassifierOptions& options = {});

/// {"policies": [{"name", "summary": {view: {mode: {group: bool}}}, "checks": [{"group",
/// "mode", "view", "method", "equivariant", "max_error", "cases", "seed", "witness", ...}]}]}
/// With `interface` (a plug-in's, policy_interface.hpp), each entry also carries "interface":
/// its state and action layouts, outputs, hands, rng and episodes.
std::string policy_audit_json(const std::vector<Classification>& policies,
                              const PolicyInterface* interface = nullptr);

}  // namespace handcentric::props
