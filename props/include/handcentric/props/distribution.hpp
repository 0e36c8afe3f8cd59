#pragma once
// In-distribution invariance (Sec. 5 vs App. A.4): with eps ~ N(0, I) redrawn, are the samples
// of a flow target's input (or regression target) for a scene s and for g * s drawn from the
// same distribution? ActionFlow's target R_k^T (p_k - eps) (eq. 29) is, for rotations about
// the origin (N(0, I) is rotation invariant), though not pointwise; it is not, for translations.
//
// Per case (s, g): if f(g s, eps_i) = f(s, eps_i) within the pointwise tolerance for every
// draw, the two distributions are one (p = 1). Otherwise the energy distance (Szekely & Rizzo)
// between f(s, eps_i) and f(g s, eps'_i), with independent draws eps', and its permutation
// p-value decide. docs/AUDIT.md has the numbers (samples, permutations, level) and why.
#include <Eigen/Core>
#include <cstdint>
#include <memory>

#include "handcentric/core/flow_target.hpp"
#include "handcentric/props/check.hpp"

namespace handcentric::props {

/// Energy distance between the rows of x and the rows of y:
///   2 E|X - Y| - E|X - X'| - E|Y - Y'| (V-statistic). Zero iff the samples coincide as sets.
/// Throws InvalidArgument for empty samples or different column counts.
double energy_distance(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y);

struct TwoSampleResult {
  double energy_distance = 0.0;
  double p_value = 1.0;  ///< (1 + #{permuted >= observed}) / (1 + permutations)
};

/// Permutation test of "x and y come from the same distribution"; deterministic given `seed`.
/// With stop_above > 0 the test stops as soon as its p-value is sure to be >= stop_above and
/// returns Besag & Clifford's sequential estimate (1 + exceedances) / (1 + permutations done):
/// a test at level stop_above decides the same, and a sample that is clearly not different
/// costs a handful of permutations instead of all of them.
TwoSampleResult energy_test(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y, int permutations,
                            std::uint64_t seed, double stop_above = 0.0);

struct DistributionOptions {
  int cases = 10;               ///< (scene, g) pairs tested
  int samples = 32;             ///< eps draws per scene (each sample has this many rows)
  double family_alpha = 0.01;   ///< per check, split evenly over the cases (Bonferroni)
  int shrink_budget = 20;       ///< evaluations spent shrinking a witness (each is a full test)
};

/// Permutations used for a per-case level alpha: enough that p can fall below it twice over.
int permutations_for(double alpha_per_case);

/// The flow target's `component` (flow_input or flow_target) is invariant in distribution
/// under `group`: the energy test keeps p >= family_alpha / cases on every case. Uses
/// options.seed (cases), options.noise_seed (eps draws), options.flow_time, options.shape.
Verdict check_distribution_invariance(std::shared_ptr<const FlowTarget> target, Component component,
                                      Group group, const CheckOptions& options = {},
                                      const DistributionOptions& distribution = {});

}  // namespace handcentric::props
