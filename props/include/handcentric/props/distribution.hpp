#pragma once
// In-distribution invariance (Sec. 5 vs App. A.4): with eps ~ N(0, I), is the law of a flow
// target's input (or regression target) for a scene s the same as for g * s? ActionFlow's
// target R_k^T (p_k - eps) (eq. 29) is, for rotations about the origin (N(0, I) is rotation
// invariant), though not pointwise; it is not, for translations.
//
// Per case (s, g), two ways to decide, chosen by what the component is:
//   exact_gaussian: when f(s, eps) is affine in eps, f(s, eps) = f(s, 0) + J eps (probed at
//     eps = 0 and the unit vectors, then verified at random eps), its law is N(f(s, 0), J J^T).
//     Two Gaussian laws are equal iff their means and covariances are: compared up to rounding.
//     This covers the rectified flow of every representation (a - eps, t a + (1 - t) eps) and
//     ActionFlow's target: the question has an exact answer, so no test is run.
//   energy_test: otherwise, two tests at half the level each (or p = 1 when f(g s, eps_i) =
//     f(s, eps_i) on every shared draw): the energy distance (Szekely & Rizzo) between
//     f(s, eps_i) and f(g s, eps'_i) with its permutation p-value, and a paired test of the mean
//     of f(s, eps_i) - f(g s, eps_i), which equal laws make zero. A "yes" then means "no
//     difference found", and the verdict states the smallest mean shift the energy test alone
//     finds with 90% power (energy_test_detectable_shift; the pair finds at least as much).
// docs/AUDIT.md has the numbers (samples, permutations, level) and why.
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>

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
  int cases = 10;    ///< (scene, g) pairs tested
  int samples = 32;  ///< energy test: eps draws per scene (each sample has this many rows)
  double family_alpha = 0.01;  ///< energy test: per check, split evenly over the cases (Bonferroni)
  int shrink_budget = 20;      ///< evaluations spent shrinking a witness
  int affinity_checks = 2;     ///< random eps at which an affine law is verified, per scene
};

/// Permutations used for a per-case level alpha: enough that p can fall below it twice over.
int permutations_for(double alpha_per_case);

/// Two-sided p-value of Student's t statistic `t` with the given degrees of freedom.
double student_t_two_sided_p(double t, double degrees_of_freedom);

/// The paired test of "the rows of `differences` have mean zero": Student's t per column,
/// Bonferroni over the columns (a column with no spread above `tolerance` rejects when its mean
/// is above it). Returns the adjusted p-value.
double paired_mean_test(const Eigen::MatrixXd& differences, double tolerance);

/// The law of f(eps), eps ~ N(0, I), when f is affine: f(eps) = mean + noise_map eps, so the
/// law is N(mean, noise_map noise_map^T).
struct GaussianLaw {
  Eigen::VectorXd mean;
  Eigen::MatrixXd noise_map;  ///< J, one column per noise coordinate
};

/// Probes f at eps = 0 and at the n unit vectors (n + 1 evaluations), then verifies
/// f(eps) = mean + J eps within `tolerance` (inf-norm) at `checks` standard normal eps drawn
/// from mt19937_64(seed). Returns nullopt when a verification fails or f changes length: f is
/// not affine in eps (as far as the checks see).
std::optional<GaussianLaw> affine_law(
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f, Eigen::Index n,
    double tolerance, std::uint64_t seed, int checks = 2);

/// How far apart two Gaussian laws are: |mean_a - mean_b|_inf and |J_a J_a^T - J_b J_b^T|_inf
/// (infinite when their dimensions differ). Both zero iff the laws are equal.
struct LawDifference {
  double mean = 0.0;
  double covariance = 0.0;
  double covariance_scale = 1.0;  ///< max(1, largest |covariance entry|): scales its tolerance
};
LawDifference law_difference(const GaussianLaw& a, const GaussianLaw& b);

/// The smallest mean shift (Euclidean norm, in units of the noise's standard deviation) that
/// the energy test of this file detects with 90% power between two samples of `samples` rows
/// of isotropic Gaussian noise in `dimension` dimensions, at level `alpha`. Measured by
/// simulation (100 tests per shift, bisection; deterministic), with the dimension rounded up
/// to a power of two (power falls with dimension, so the figure errs on the large side).
/// Cached per (dimension, samples, alpha). Costs about a second the first time.
double energy_test_detectable_shift(Eigen::Index dimension, int samples, double alpha);

/// The flow target's `component` (flow_input or flow_target) is invariant in distribution
/// under `group` (exactly where it is affine in eps, by the energy test elsewhere: see the top
/// of this file). Uses options.seed (cases), options.noise_seed (eps draws), options.flow_time,
/// options.shape, options.relative_tolerance. The verdict's method says how it was decided.
Verdict check_distribution_invariance(std::shared_ptr<const FlowTarget> target, Component component,
                                      Group group, const CheckOptions& options = {},
                                      const DistributionOptions& distribution = {});

}  // namespace handcentric::props
