#include "handcentric/props/distribution.hpp"

#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <numeric>
#include <random>
#include <tuple>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/props/tolerance.hpp"
#include "check_runner.hpp"

namespace handcentric::props {
namespace {

// The energy distance of a split of the pooled sample (x_rows: the rows in x, the others in y),
// from the pooled distances D and its total pair sum. With S_xx, S_yy, S_xy the sums over
// pairs (i < j) inside x, inside y and across, the V-statistic is
//   2 S_xy / (n m) - 2 S_xx / n^2 - 2 S_yy / m^2,
// and S_xx + S_yy = total - S_xy, so only the cross sum is needed when n = m; for n != m the
// inside sums are computed too.
double split_energy(const Eigen::MatrixXd& D, const std::vector<Eigen::Index>& order,
                    Eigen::Index n) {
  const Eigen::Index N = static_cast<Eigen::Index>(order.size()), m = N - n;
  double xx = 0.0, yy = 0.0, xy = 0.0;
  for (Eigen::Index a = 0; a < N; ++a) {
    const Eigen::Index i = order[static_cast<std::size_t>(a)];
    for (Eigen::Index b = a + 1; b < N; ++b) {
      const double d = D(i, order[static_cast<std::size_t>(b)]);
      if (b < n) {
        xx += d;
      } else if (a >= n) {
        yy += d;
      } else {
        xy += d;
      }
    }
  }
  const double dn = static_cast<double>(n), dm = static_cast<double>(m);
  return 2.0 * xy / (dn * dm) - 2.0 * xx / (dn * dn) - 2.0 * yy / (dm * dm);
}

// The same for n = m, from the cross sum alone (half the work: the permutation loop).
double split_energy_equal(const Eigen::MatrixXd& D, const std::vector<Eigen::Index>& order,
                          Eigen::Index n, double total) {
  double xy = 0.0;
  for (Eigen::Index a = 0; a < n; ++a) {
    const Eigen::Index i = order[static_cast<std::size_t>(a)];
    for (Eigen::Index b = n; b < 2 * n; ++b) xy += D(i, order[static_cast<std::size_t>(b)]);
  }
  const double dn = static_cast<double>(n);
  return (2.0 * xy - 2.0 * (total - xy)) / (dn * dn);
}

void require_samples(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y) {
  if (x.rows() == 0 || y.rows() == 0 || x.cols() != y.cols()) {
    throw InvalidArgument(
        "energy distance needs two non-empty samples of the same dimension, got " +
        std::to_string(x.rows()) + " x " + std::to_string(x.cols()) + " and " +
        std::to_string(y.rows()) + " x " + std::to_string(y.cols()));
  }
}

Eigen::MatrixXd pooled_distances(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y) {
  Eigen::MatrixXd z(x.rows() + y.rows(), x.cols());
  z << x, y;
  const Eigen::Index N = z.rows();
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(N, N);
  for (Eigen::Index j = 1; j < N; ++j) {
    for (Eigen::Index i = 0; i < j; ++i) D(i, j) = D(j, i) = (z.row(i) - z.row(j)).norm();
  }
  return D;
}

// The regularized incomplete beta function I_x(a, b), by its continued fraction (modified Lentz),
// on the side of x where the fraction converges fast (x < (a + 1) / (a + b + 2)).
double incomplete_beta(double a, double b, double x) {
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  if (x > (a + 1.0) / (a + b + 2.0)) return 1.0 - incomplete_beta(b, a, 1.0 - x);
  const double front = std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) +
                                a * std::log(x) + b * std::log1p(-x)) /
                       a;
  constexpr double kTiny = 1e-300;
  double f = 1.0, c = 1.0, d = 0.0;
  for (int i = 0; i <= 400; ++i) {
    const int m = i / 2;
    double numerator;
    if (i == 0) {
      numerator = 1.0;
    } else if (i % 2 == 0) {
      numerator = (m * (b - m) * x) / ((a + 2.0 * m - 1.0) * (a + 2.0 * m));
    } else {
      numerator = -((a + m) * (a + b + m) * x) / ((a + 2.0 * m) * (a + 2.0 * m + 1.0));
    }
    d = 1.0 + numerator * d;
    d = 1.0 / (std::abs(d) < kTiny ? kTiny : d);
    c = 1.0 + numerator / c;
    if (std::abs(c) < kTiny) c = kTiny;
    f *= c * d;
    if (std::abs(1.0 - c * d) < 1e-14) break;
  }
  return front * (f - 1.0);
}

}  // namespace

double student_t_two_sided_p(double t, double degrees_of_freedom) {
  if (!(degrees_of_freedom > 0.0))
    throw InvalidArgument("Student's t needs positive degrees of freedom");
  if (!std::isfinite(t)) return std::isnan(t) ? 1.0 : 0.0;
  return incomplete_beta(0.5 * degrees_of_freedom, 0.5,
                         degrees_of_freedom / (degrees_of_freedom + t * t));
}

double paired_mean_test(const Eigen::MatrixXd& differences, double tolerance) {
  const Eigen::Index n = differences.rows(), d = differences.cols();
  if (n < 2 || d == 0) return 1.0;
  double smallest = 1.0;
  for (Eigen::Index j = 0; j < d; ++j) {
    const Eigen::VectorXd column = differences.col(j);
    const double mean = column.mean();
    const double sd =
        std::sqrt((column.array() - mean).square().sum() / static_cast<double>(n - 1));
    if (!(sd > tolerance)) {
      // No spread: the mean difference is a constant, seen exactly.
      if (std::abs(mean) > tolerance) return 0.0;
      continue;
    }
    smallest = std::min(
        smallest, student_t_two_sided_p(mean / (sd / std::sqrt(static_cast<double>(n))), n - 1.0));
  }
  return std::min(1.0, smallest * static_cast<double>(d));  // Bonferroni over the coordinates
}

double energy_distance(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y) {
  require_samples(x, y);
  std::vector<Eigen::Index> order(static_cast<std::size_t>(x.rows() + y.rows()));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  return split_energy(pooled_distances(x, y), order, x.rows());
}

TwoSampleResult energy_test(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y, int permutations,
                            std::uint64_t seed, double stop_above) {
  require_samples(x, y);
  if (permutations < 1)
    throw InvalidArgument("a permutation test needs at least 1 permutation, got " +
                          std::to_string(permutations));
  const Eigen::MatrixXd D = pooled_distances(x, y);
  const Eigen::Index n = x.rows();
  std::vector<Eigen::Index> order(static_cast<std::size_t>(x.rows() + y.rows()));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  const bool equal = x.rows() == y.rows();
  const double total = 0.5 * D.sum();
  TwoSampleResult result;
  result.energy_distance = split_energy(D, order, n);
  std::mt19937_64 rng(seed);
  int at_least = 0;
  for (int b = 0; b < permutations; ++b) {
    // Fisher-Yates; each 64-bit draw gives two indices (32 bits each, multiply-shift into
    // [0, i], bias below 2^-25 for samples under 128 rows): the shuffle is the hot loop.
    std::uint64_t bits = 0;
    for (std::size_t i = order.size() - 1, used = 2; i > 0; --i, ++used) {
      if (used == 2) {
        bits = rng();
        used = 0;
      }
      const std::uint64_t word = bits & 0xffffffffULL;
      bits >>= 32;
      const auto j = static_cast<std::size_t>((word * static_cast<std::uint64_t>(i + 1)) >> 32);
      std::swap(order[i], order[j]);
    }
    const double permuted =
        equal ? split_energy_equal(D, order, n, total) : split_energy(D, order, n);
    // A relative slack: a split that equals the observed one up to rounding counts as >=.
    if (permuted >= result.energy_distance - 1e-12 * std::abs(result.energy_distance)) ++at_least;
    // Besag & Clifford (1991): once the p-value cannot fall below stop_above, stop and report
    // the sequential estimate (1 + at_least) / (1 + permutations done).
    if (stop_above > 0.0 && (1.0 + at_least) / (1.0 + permutations) >= stop_above) {
      result.p_value = (1.0 + at_least) / (2.0 + b);
      return result;
    }
  }
  result.p_value = (1.0 + at_least) / (1.0 + permutations);
  return result;
}

int permutations_for(double alpha_per_case) {
  // p can be as small as 1 / (B + 1): ask for B + 1 >= 2 / alpha.
  return std::max(99, static_cast<int>(std::ceil(2.0 / alpha_per_case)) - 1);
}

std::optional<GaussianLaw> affine_law(
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f, Eigen::Index n,
    double tolerance, std::uint64_t seed, int checks) {
  if (n < 0)
    throw InvalidArgument("affine_law needs a noise dimension >= 0, got " + std::to_string(n));
  GaussianLaw law;
  Eigen::VectorXd eps = Eigen::VectorXd::Zero(n);
  law.mean = f(eps);
  std::mt19937_64 rng(seed);
  auto normals = [&rng, n] {
    Eigen::VectorXd v(n);
    for (Eigen::Index j = 0; j < n; ++j) v(j) = standard_normal(rng);
    return v;
  };
  // A cheap necessary test first (4 evaluations, where probing takes n + 1): an affine map is
  // additive about f(0). Most maps that are not affine (a sampler through a network) fail it.
  {
    const Eigen::VectorXd u = normals(), v = normals();
    const Eigen::VectorXd fu = f(u), fv = f(v), fuv = f(u + v);
    if (fu.size() != law.mean.size() || fv.size() != law.mean.size() ||
        fuv.size() != law.mean.size())
      return std::nullopt;
    if (law.mean.size() > 0 &&
        !((fuv - fu - fv + law.mean).cwiseAbs().maxCoeff() <= 2.0 * tolerance))
      return std::nullopt;
  }
  law.noise_map.resize(law.mean.size(), n);
  for (Eigen::Index j = 0; j < n; ++j) {
    eps(j) = 1.0;
    const Eigen::VectorXd column = f(eps);
    eps(j) = 0.0;
    if (column.size() != law.mean.size()) return std::nullopt;
    law.noise_map.col(j) = column - law.mean;
  }
  // Affine maps agree with mean + J eps everywhere; verify it where nothing was probed.
  for (int c = 0; c < checks; ++c) {
    eps = normals();
    const Eigen::VectorXd value = f(eps);
    if (value.size() != law.mean.size()) return std::nullopt;
    const Eigen::VectorXd predicted = law.mean + law.noise_map * eps;
    if (value.size() > 0 && !((value - predicted).cwiseAbs().maxCoeff() <= tolerance))
      return std::nullopt;
  }
  return law;
}

LawDifference law_difference(const GaussianLaw& a, const GaussianLaw& b) {
  LawDifference difference;
  if (a.mean.size() != b.mean.size() || a.noise_map.rows() != b.noise_map.rows()) {
    difference.mean = difference.covariance = std::numeric_limits<double>::infinity();
    return difference;
  }
  if (a.mean.size() == 0) return difference;
  difference.mean = (a.mean - b.mean).cwiseAbs().maxCoeff();
  // Equal noise maps give equal covariances, the common case (a rectified flow's J is the same
  // for every scene): skip the two products then.
  const bool same_map = a.noise_map.cols() == b.noise_map.cols() && a.noise_map == b.noise_map;
  const Eigen::MatrixXd covariance_a = a.noise_map * a.noise_map.transpose();
  difference.covariance_scale = std::max(1.0, covariance_a.cwiseAbs().maxCoeff());
  if (same_map) return difference;
  const Eigen::MatrixXd covariance_b = b.noise_map * b.noise_map.transpose();
  difference.covariance_scale =
      std::max(difference.covariance_scale, covariance_b.cwiseAbs().maxCoeff());
  difference.covariance = (covariance_a - covariance_b).cwiseAbs().maxCoeff();
  return difference;
}

double energy_test_detectable_shift(Eigen::Index dimension, int samples, double alpha) {
  if (dimension < 1 || samples < 2 || !(alpha > 0.0 && alpha < 1.0)) {
    throw InvalidArgument(
        "energy_test_detectable_shift needs dimension >= 1, samples >= 2 and 0 < alpha < 1, got " +
        std::to_string(dimension) + ", " + std::to_string(samples) + ", " + format_number(alpha));
  }
  Eigen::Index rounded = 1;
  while (rounded < dimension) rounded *= 2;
  static std::mutex mutex;
  static std::map<std::tuple<Eigen::Index, int, double>, double> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  const auto key = std::make_tuple(rounded, samples, alpha);
  if (const auto hit = cache.find(key); hit != cache.end()) return hit->second;
  constexpr int kRepetitions = 100;
  constexpr double kPower = 0.9;
  const int permutations = permutations_for(alpha);
  // The fraction of kRepetitions tests (the same draws for every shift) that reject at `alpha`
  // when the second sample's mean is moved by `shift` along the first axis (the test is
  // rotation invariant, so the direction does not matter).
  auto power = [&](double shift) {
    std::mt19937_64 rng(20261201);
    int rejected = 0;
    Eigen::MatrixXd x(samples, rounded), y(samples, rounded);
    for (int r = 0; r < kRepetitions; ++r) {
      for (Eigen::Index i = 0; i < x.size(); ++i) x.data()[i] = standard_normal(rng);
      for (Eigen::Index i = 0; i < y.size(); ++i) y.data()[i] = standard_normal(rng);
      y.col(0).array() += shift;
      if (energy_test(x, y, permutations, rng(), alpha).p_value < alpha) ++rejected;
    }
    return static_cast<double>(rejected) / kRepetitions;
  };
  double low = 0.0, high = 1.0;
  while (power(high) < kPower) {
    low = high;
    high *= 2.0;
    if (high > 1e6) break;  // cannot happen for samples >= 2 and alpha > 1 / permutations
  }
  for (int step = 0; step < 6; ++step) {  // the bracket to 1/64: a figure to 2%
    const double middle = 0.5 * (low + high);
    (power(middle) >= kPower ? high : low) = middle;
  }
  cache.emplace(key, high);
  return high;
}

namespace detail {

CaseOutcome compare_laws(const NoisePair& pair, double tolerance, const CheckOptions& options,
                         const DistributionOptions& distribution, LawStatistics& statistics) {
  const double alpha = distribution.family_alpha / distribution.cases;  // Bonferroni
  const int samples = distribution.samples;
  CaseOutcome outcome;
  const std::optional<GaussianLaw> law =
      affine_law(pair.before, pair.noise_dimension, tolerance, options.noise_seed,
                 distribution.affinity_checks);
  const std::optional<GaussianLaw> moved_law =
      law ? affine_law(pair.after, pair.noise_dimension, tolerance, options.noise_seed,
                       distribution.affinity_checks)
          : std::nullopt;
  if (law && moved_law) {
    // Exact: two Gaussian laws are one iff their means and covariances agree.
    const LawDifference difference = law_difference(*law, *moved_law);
    const double covariance_tolerance = tolerance * difference.covariance_scale;
    outcome.witness.before = law->mean;
    outcome.witness.after = moved_law->mean;
    outcome.witness.error = std::max(difference.mean, difference.covariance);
    outcome.witness.tolerance = tolerance;
    outcome.witness.detail =
        "Gaussian laws (affine in eps): means differ by " + format_number(difference.mean) +
        ", covariances by " + format_number(difference.covariance) + " (tolerance " +
        format_number(tolerance) + ", covariance " + format_number(covariance_tolerance) + ")";
    outcome.holds = difference.mean <= tolerance && difference.covariance <= covariance_tolerance;
    return outcome;
  }
  statistics.any_energy = true;
  const Eigen::Index noise = pair.noise_dimension;
  std::mt19937_64 shared(options.noise_seed), fresh(options.noise_seed ^ 0x9e3779b97f4a7c15ULL);
  auto draw = [noise](std::mt19937_64& rng) {
    Eigen::VectorXd eps(noise);
    for (Eigen::Index j = 0; j < noise; ++j) eps(j) = standard_normal(rng);
    return eps;
  };
  // x: before(eps_i); same_eps: after(eps_i) (the same draws); y: after(eps'_i) (fresh draws).
  Eigen::MatrixXd x, same_eps;
  double pointwise = 0.0;
  for (int i = 0; i < samples; ++i) {
    const Eigen::VectorXd eps = draw(shared);
    const Eigen::VectorXd u = pair.before(eps);
    const Eigen::VectorXd v = pair.after(eps);
    if (i == 0) {
      x.resize(samples, u.size());
      same_eps.resize(samples, v.size());
    }
    if (u.size() != x.cols() || v.size() != same_eps.cols()) {
      throw InvalidArgument(pair.name + " changed length between noise draws");
    }
    x.row(i) = u.transpose();
    same_eps.row(i) = v.transpose();
    pointwise = u.size() == v.size()
                    ? std::max(pointwise, u.size() ? (u - v).lpNorm<Eigen::Infinity>() : 0.0)
                    : std::numeric_limits<double>::infinity();
  }
  statistics.largest_dimension = std::max(statistics.largest_dimension, x.cols());
  if (x.cols() > 0) {
    const Eigen::RowVectorXd mean = x.colwise().mean();
    const double variance =
        (x.rowwise() - mean).squaredNorm() / (static_cast<double>(samples - 1) * x.cols());
    statistics.largest_spread = std::max(statistics.largest_spread, std::sqrt(variance));
  }
  outcome.witness.before = x.row(0).transpose();
  outcome.witness.tolerance = alpha;
  if (pointwise <= tolerance) {
    // The same value on every shared draw: the two distributions are the same one, no test needed.
    outcome.witness.after = same_eps.row(0).transpose();
    outcome.witness.error = energy_distance(x, same_eps);
    outcome.witness.p_value = 1.0;
    return outcome;
  }
  if (x.cols() != same_eps.cols()) {  // different lengths: different laws
    outcome.witness.after = same_eps.row(0).transpose();
    outcome.witness.error = std::numeric_limits<double>::infinity();
    outcome.witness.p_value = 0.0;
    outcome.holds = false;
    return outcome;
  }
  // Not pointwise: test before(eps) against after(eps') with independent draws (a permutation
  // test needs exchangeable samples; shared draws would not be).
  // Two tests at alpha / 2 each: the energy test (a permutation test: exact level, little power
  // against a mean shift in many dimensions) and the paired test of the mean difference on the
  // shared draws (equal laws have equal means, so E[before - after] = 0: Student's t per
  // coordinate, Bonferroni; its level is asymptotic, and a mean that moves by a constant, as
  // when a policy mixes frames, stands out at once).
  Eigen::MatrixXd y(samples, same_eps.cols());
  for (int i = 0; i < samples; ++i) y.row(i) = pair.after(draw(fresh)).transpose();
  const TwoSampleResult test =
      energy_test(x, y, permutations_for(0.5 * alpha), options.seed, 0.5 * alpha);
  const double paired = paired_mean_test(x - same_eps, tolerance);
  outcome.witness.after = y.row(0).transpose();
  outcome.witness.error = test.energy_distance;
  outcome.witness.p_value = std::min(1.0, 2.0 * std::min(test.p_value, paired));
  outcome.witness.detail = "energy test p = " + format_number(test.p_value) +
                           ", paired mean test p = " + format_number(paired) + " (each at level " +
                           format_number(0.5 * alpha) + ")";
  outcome.holds = test.p_value >= 0.5 * alpha && paired >= 0.5 * alpha;
  return outcome;
}

void finish_distribution_verdict(Verdict& verdict, const LawStatistics& statistics,
                                 const DistributionOptions& distribution) {
  verdict.method = statistics.any_energy ? Method::energy_test : Method::exact_gaussian;
  if (verdict.method == Method::energy_test && verdict.invariant &&
      statistics.largest_dimension > 0) {
    verdict.detectable_shift =
        energy_test_detectable_shift(statistics.largest_dimension, distribution.samples,
                                     distribution.family_alpha / distribution.cases) *
        statistics.largest_spread;
  }
}

void require_distribution_options(const DistributionOptions& distribution) {
  if (distribution.cases < 1 || distribution.samples < 2 ||
      !(distribution.family_alpha > 0.0 && distribution.family_alpha < 1.0) ||
      distribution.affinity_checks < 1) {
    throw InvalidArgument(
        "distribution options need cases >= 1, samples >= 2, 0 < alpha < 1 and affinity_checks >= "
        "1, got cases " +
        std::to_string(distribution.cases) + ", samples " + std::to_string(distribution.samples) +
        ", alpha " + format_number(distribution.family_alpha) + ", affinity_checks " +
        std::to_string(distribution.affinity_checks));
  }
}

}  // namespace detail

Verdict check_distribution_invariance(std::shared_ptr<const FlowTarget> target, Component component,
                                      Group group, const CheckOptions& options,
                                      const DistributionOptions& distribution) {
  if (!target) throw InvalidArgument("check_distribution_invariance needs a flow target, got null");
  if (component != Component::flow_input && component != Component::flow_target) {
    throw InvalidArgument("in-distribution checks are about flow_input or flow_target, got " +
                          to_string(component));
  }
  detail::require_distribution_options(distribution);
  detail::LawStatistics statistics;
  auto run_case = [&](const Scene& scene, const RigidTransform& g) {
    const Scene moved = g * scene;
    auto part_of = [&](const Scene& s) {
      return [&target, &options, component, s](const Eigen::VectorXd& eps) -> Eigen::VectorXd {
        const FlowSample sample = (*target)(s, eps, options.flow_time);
        return component == Component::flow_input ? sample.input : sample.target;
      };
    };
    const detail::NoisePair pair{part_of(scene), part_of(moved), target->noise_dimension(scene),
                                 target->name() + ": the " + to_string(component)};
    detail::CaseOutcome outcome =
        detail::compare_laws(pair, pointwise_tolerance(scene, moved, options.relative_tolerance),
                             options, distribution, statistics);
    outcome.witness.scene = scene;
    outcome.witness.g = g;
    return outcome;
  };
  Verdict verdict = detail::run_check(run_case, component, group, Mode::distribution, options,
                                      distribution.cases, distribution.shrink_budget);
  detail::finish_distribution_verdict(verdict, statistics, distribution);
  return verdict;
}

}  // namespace handcentric::props
