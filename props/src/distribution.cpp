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
double split_energy(const Eigen::MatrixXd& D, const std::vector<Eigen::Index>& order, Eigen::Index n) {
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
double split_energy_equal(const Eigen::MatrixXd& D, const std::vector<Eigen::Index>& order, Eigen::Index n,
                          double total) {
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
    throw InvalidArgument("energy distance needs two non-empty samples of the same dimension, got " +
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

}  // namespace

double energy_distance(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y) {
  require_samples(x, y);
  std::vector<Eigen::Index> order(static_cast<std::size_t>(x.rows() + y.rows()));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  return split_energy(pooled_distances(x, y), order, x.rows());
}

TwoSampleResult energy_test(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y, int permutations, std::uint64_t seed,
                            double stop_above) {
  require_samples(x, y);
  if (permutations < 1) throw InvalidArgument("a permutation test needs at least 1 permutation, got " + std::to_string(permutations));
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
    const double permuted = equal ? split_energy_equal(D, order, n, total) : split_energy(D, order, n);
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

std::optional<GaussianLaw> affine_law(const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
                                      Eigen::Index n, double tolerance, std::uint64_t seed, int checks) {
  if (n < 0) throw InvalidArgument("affine_law needs a noise dimension >= 0, got " + std::to_string(n));
  GaussianLaw law;
  Eigen::VectorXd eps = Eigen::VectorXd::Zero(n);
  law.mean = f(eps);
  law.noise_map.resize(law.mean.size(), n);
  for (Eigen::Index j = 0; j < n; ++j) {
    eps(j) = 1.0;
    const Eigen::VectorXd column = f(eps);
    eps(j) = 0.0;
    if (column.size() != law.mean.size()) return std::nullopt;
    law.noise_map.col(j) = column - law.mean;
  }
  // Affine maps agree with mean + J eps everywhere; verify it where nothing was probed.
  std::mt19937_64 rng(seed);
  for (int c = 0; c < checks; ++c) {
    for (Eigen::Index j = 0; j < n; ++j) eps(j) = standard_normal(rng);
    const Eigen::VectorXd value = f(eps);
    if (value.size() != law.mean.size()) return std::nullopt;
    const Eigen::VectorXd predicted = law.mean + law.noise_map * eps;
    if (value.size() > 0 && !((value - predicted).cwiseAbs().maxCoeff() <= tolerance)) return std::nullopt;
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
  difference.covariance_scale = std::max(difference.covariance_scale, covariance_b.cwiseAbs().maxCoeff());
  difference.covariance = (covariance_a - covariance_b).cwiseAbs().maxCoeff();
  return difference;
}

double energy_test_detectable_shift(Eigen::Index dimension, int samples, double alpha) {
  if (dimension < 1 || samples < 2 || !(alpha > 0.0 && alpha < 1.0)) {
    throw InvalidArgument("energy_test_detectable_shift needs dimension >= 1, samples >= 2 and 0 < alpha < 1, got " +
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

Verdict check_distribution_invariance(std::shared_ptr<const FlowTarget> target, Component component, Group group,
                                      const CheckOptions& options, const DistributionOptions& distribution) {
  if (!target) throw InvalidArgument("check_distribution_invariance needs a flow target, got null");
  if (component != Component::flow_input && component != Component::flow_target) {
    throw InvalidArgument("in-distribution checks are about flow_input or flow_target, got " + to_string(component));
  }
  if (distribution.cases < 1 || distribution.samples < 2 || !(distribution.family_alpha > 0.0 && distribution.family_alpha < 1.0) ||
      distribution.affinity_checks < 1) {
    throw InvalidArgument("distribution options need cases >= 1, samples >= 2, 0 < alpha < 1 and affinity_checks >= 1, got cases " +
                          std::to_string(distribution.cases) + ", samples " + std::to_string(distribution.samples) +
                          ", alpha " + format_number(distribution.family_alpha) + ", affinity_checks " +
                          std::to_string(distribution.affinity_checks));
  }
  const double alpha = distribution.family_alpha / distribution.cases;  // Bonferroni
  const int permutations = permutations_for(alpha);
  const int samples = distribution.samples;
  auto part = [component](const FlowSample& sample) -> const Eigen::VectorXd& {
    return component == Component::flow_input ? sample.input : sample.target;
  };
  bool any_energy = false;
  Eigen::Index largest_dimension = 0;
  double largest_spread = 0.0;  // the RMS per-coordinate standard deviation, largest over energy cases
  auto law_of = [&](const Scene& scene, double tolerance) {
    const auto f = [&](const Eigen::VectorXd& eps) { return part((*target)(scene, eps, options.flow_time)); };
    return affine_law(f, target->noise_dimension(scene), tolerance, options.noise_seed, distribution.affinity_checks);
  };
  auto run_case = [&](const Scene& scene, const RigidTransform& g) {
    const Scene moved = g * scene;
    const double tolerance = pointwise_tolerance(scene, moved, options.relative_tolerance);
    detail::CaseOutcome outcome;
    outcome.witness.scene = scene;
    outcome.witness.g = g;
    const std::optional<GaussianLaw> law = law_of(scene, tolerance);
    const std::optional<GaussianLaw> moved_law = law ? law_of(moved, tolerance) : std::nullopt;
    if (law && moved_law) {
      // Exact: two Gaussian laws are one iff their means and covariances agree.
      const LawDifference difference = law_difference(*law, *moved_law);
      const double covariance_tolerance = tolerance * difference.covariance_scale;
      outcome.witness.before = law->mean;
      outcome.witness.after = moved_law->mean;
      outcome.witness.error = std::max(difference.mean, difference.covariance);
      outcome.witness.tolerance = tolerance;
      outcome.witness.detail = "Gaussian laws (affine in eps): means differ by " + format_number(difference.mean) +
                               ", covariances by " + format_number(difference.covariance) + " (tolerance " +
                               format_number(tolerance) + ", covariance " + format_number(covariance_tolerance) + ")";
      outcome.holds = difference.mean <= tolerance && difference.covariance <= covariance_tolerance;
      return outcome;
    }
    any_energy = true;
    const Eigen::Index noise = target->noise_dimension(scene);
    std::mt19937_64 shared(options.noise_seed), fresh(options.noise_seed ^ 0x9e3779b97f4a7c15ULL);
    auto draw = [noise](std::mt19937_64& rng) {
      Eigen::VectorXd eps(noise);
      for (Eigen::Index j = 0; j < noise; ++j) eps(j) = standard_normal(rng);
      return eps;
    };
    // x: f(s, eps_i); same_eps: f(g s, eps_i) (the same draws); y: f(g s, eps'_i) (fresh draws).
    Eigen::MatrixXd x, same_eps;
    double pointwise = 0.0;
    for (int i = 0; i < samples; ++i) {
      const Eigen::VectorXd eps = draw(shared);
      const Eigen::VectorXd u = part((*target)(scene, eps, options.flow_time));
      const Eigen::VectorXd v = part((*target)(moved, eps, options.flow_time));
      if (i == 0) {
        x.resize(samples, u.size());
        same_eps.resize(samples, v.size());
      }
      if (u.size() != x.cols() || v.size() != same_eps.cols()) {
        throw InvalidArgument(target->name() + ": the " + to_string(component) + " changed length between noise draws");
      }
      x.row(i) = u.transpose();
      same_eps.row(i) = v.transpose();
      pointwise = u.size() == v.size() ? std::max(pointwise, u.size() ? (u - v).lpNorm<Eigen::Infinity>() : 0.0)
                                       : std::numeric_limits<double>::infinity();
    }
    largest_dimension = std::max(largest_dimension, x.cols());
    if (x.cols() > 0) {
      const Eigen::RowVectorXd mean = x.colwise().mean();
      const double variance = (x.rowwise() - mean).squaredNorm() / (static_cast<double>(samples - 1) * x.cols());
      largest_spread = std::max(largest_spread, std::sqrt(variance));
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
    // Not pointwise: test f(s, eps) against f(g s, eps') with independent draws (a permutation
    // test needs exchangeable samples; shared draws would not be).
    Eigen::MatrixXd y(samples, same_eps.cols());
    for (int i = 0; i < samples; ++i) y.row(i) = part((*target)(moved, draw(fresh), options.flow_time)).transpose();
    const TwoSampleResult test = energy_test(x, y, permutations, options.seed, alpha);
    outcome.witness.after = y.row(0).transpose();
    outcome.witness.error = test.energy_distance;
    outcome.witness.p_value = test.p_value;
    outcome.holds = test.p_value >= alpha;
    return outcome;
  };
  Verdict verdict = detail::run_check(run_case, component, group, Mode::distribution, options, distribution.cases,
                                      distribution.shrink_budget);
  verdict.method = any_energy ? Method::energy_test : Method::exact_gaussian;
  if (verdict.method == Method::energy_test && verdict.invariant && largest_dimension > 0) {
    verdict.detectable_shift = energy_test_detectable_shift(largest_dimension, samples, alpha) * largest_spread;
  }
  return verdict;
}

}  // namespace handcentric::props
