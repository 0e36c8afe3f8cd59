#pragma once
// The statistics of the in-distribution checks (distribution.hpp says how a check uses them):
// the energy distance and its permutation test, the paired test of a mean difference (Student's
// t), the permutation test of scale, and the power of the two permutation tests: the smallest
// mean shift and standard-deviation ratio each finds with 90% power. docs/AUDIT.md has the
// numbers (samples, permutations, level) and why.
#include <Eigen/Core>
#include <cstdint>

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

/// Permutations used for a per-case level alpha: enough that p can fall below it twice over.
int permutations_for(double alpha_per_case);

/// Two-sided p-value of Student's t statistic `t` with the given degrees of freedom (> 0;
/// infinite: the normal's): 1 for t = 0 or NaN, 0 for an infinite t. Throws InvalidArgument for
/// degrees of freedom that are not positive.
double student_t_two_sided_p(double t, double degrees_of_freedom);

/// The paired test of "the rows of `differences` have mean zero": Student's t per column,
/// Bonferroni over the columns (a column with no spread above `tolerance` rejects when its mean
/// is above it). Returns the adjusted p-value.
double paired_mean_test(const Eigen::MatrixXd& differences, double tolerance);

/// The smallest mean shift (Euclidean norm, in units of the noise's standard deviation) that
/// the energy test of this file detects with 90% power between two samples of `samples` rows
/// of isotropic Gaussian noise in `dimension` dimensions, at level `alpha`. Measured by
/// simulation (100 tests per shift, bisection; deterministic), with the dimension rounded up
/// to a power of two (power falls with dimension, so the figure errs on the large side).
/// Tabulated at the audit's defaults (samples 32, alpha kDefaultTestLevel, dimension up to 1024);
/// otherwise simulated once and cached per (dimension, samples, alpha), which costs 1 to 15 s.
double energy_test_detectable_shift(Eigen::Index dimension, int samples, double alpha);

/// The simulation behind energy_test_detectable_shift, run every time (no table, no cache).
double simulated_energy_test_detectable_shift(Eigen::Index dimension, int samples, double alpha);

/// The level of each test in a case at the default DistributionOptions: 0.01 per check over 10
/// cases, a third to each of the three tests.
inline constexpr double kDefaultTestLevel = 0.01 / 10 / 3.0;

struct ScaleTestResult {
  double statistic = 0.0;        ///< the largest standardized difference over the coordinates
  Eigen::Index coordinate = -1;  ///< where it is (-1: no coordinate with spread)
  double sd_ratio = 1.0;         ///< sd of y over sd of x in that coordinate
  double p_value = 1.0;          ///< (1 + #{permuted >= observed}) / (1 + permutations)
};

/// Permutation test of "x and y come from the same distribution" aimed at a change of scale in
/// one coordinate: per coordinate j, z = |w - median_j| over the pooled sample w (so z is
/// exchangeable when the laws are equal), and the statistic is the largest over j of
/// |mean of z over x - mean of z over y| / (sd_j sqrt(1/n + 1/m)), sd_j the pooled sd of z.
/// A permutation test: its level is exact for any law, with no correction for the number of
/// coordinates (the maximum is permuted). Coordinates whose pooled sd is at most `tolerance`
/// (constants, up to rounding) are left out. Deterministic given `seed`; stop_above as for
/// energy_test.
ScaleTestResult scale_test(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y, int permutations,
                           std::uint64_t seed, double stop_above = 0.0, double tolerance = 0.0);

/// The permutations scale_test gets at level alpha in a check: permutations_for(alpha), as the
/// energy test. Rejecting when p < alpha then has level alpha / 2 (permutation_level): the
/// power figures and the draws rule use that level. Five times as many permutations would bring
/// it to 0.9 alpha for a few draws fewer, at five times the cost of every rejection.
int scale_test_permutations(double alpha);

/// The level of "reject when p < alpha" for a permutation p-value (1 + exceedances) /
/// (1 + permutations) under equal laws: (ceil(alpha (permutations + 1)) - 1) / (permutations + 1).
double permutation_level(double alpha, int permutations);

/// The power of scale_test, at level alpha (its permutation_level), between two samples of
/// `samples` rows of `dimension` independent standard normal coordinates, one of which has its sd
/// multiplied by `ratio` in the second sample (equal means). The normal approximation of each
/// coordinate's statistic with the Bonferroni critical value z(alpha / (2 dimension)), which the
/// permuted maximum's is at most (up to the approximation): tests/props checks it by simulation.
double scale_test_power(double ratio, Eigen::Index dimension, int samples, double alpha);

/// The smallest sd ratio (> 1; its inverse is found as well) that scale_test detects with 90%
/// power in one of `dimension` coordinates at `samples` rows and level alpha (closed form,
/// bisection to 1e-6).
double scale_test_detectable_ratio(Eigen::Index dimension, int samples, double alpha);

/// The fewest rows per sample at which scale_test detects an sd ratio `ratio` (> 1) in one of
/// `dimension` coordinates with 90% power at level alpha.
int samples_for_scale_ratio(Eigen::Index dimension, double alpha, double ratio);

}  // namespace handcentric::props
