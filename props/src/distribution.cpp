#include "handcentric/props/distribution.hpp"

#include <cmath>
#include <limits>
#include <numeric>
#include <random>

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

Verdict check_distribution_invariance(std::shared_ptr<const FlowTarget> target, Component component, Group group,
                                      const CheckOptions& options, const DistributionOptions& distribution) {
  if (!target) throw InvalidArgument("check_distribution_invariance needs a flow target, got null");
  if (component != Component::flow_input && component != Component::flow_target) {
    throw InvalidArgument("in-distribution checks are about flow_input or flow_target, got " + to_string(component));
  }
  if (distribution.cases < 1 || distribution.samples < 2 || !(distribution.family_alpha > 0.0 && distribution.family_alpha < 1.0)) {
    throw InvalidArgument("distribution options need cases >= 1, samples >= 2 and 0 < alpha < 1, got cases " +
                          std::to_string(distribution.cases) + ", samples " + std::to_string(distribution.samples) +
                          ", alpha " + format_number(distribution.family_alpha));
  }
  const double alpha = distribution.family_alpha / distribution.cases;  // Bonferroni
  const int permutations = permutations_for(alpha);
  const int samples = distribution.samples;
  auto part = [component](const FlowSample& sample) -> const Eigen::VectorXd& {
    return component == Component::flow_input ? sample.input : sample.target;
  };
  auto run_case = [&](const Scene& scene, const RigidTransform& g) {
    const Scene moved = g * scene;
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
      x.row(i) = u.transpose();
      same_eps.row(i) = v.transpose();
      pointwise = u.size() == v.size() ? std::max(pointwise, (u - v).lpNorm<Eigen::Infinity>())
                                       : std::numeric_limits<double>::infinity();
    }
    detail::CaseOutcome outcome;
    outcome.witness.scene = scene;
    outcome.witness.g = g;
    outcome.witness.before = x.row(0).transpose();
    outcome.witness.tolerance = alpha;
    if (pointwise <= pointwise_tolerance(scene, moved, options.relative_tolerance)) {
      // Invariant pointwise on every draw: the two distributions are the same one, no test needed.
      outcome.witness.after = same_eps.row(0).transpose();
      outcome.witness.error = energy_distance(x, same_eps);
      outcome.witness.p_value = 1.0;
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
  return detail::run_check(run_case, component, group, Mode::distribution, options, distribution.cases,
                           distribution.shrink_budget);
}

}  // namespace handcentric::props
