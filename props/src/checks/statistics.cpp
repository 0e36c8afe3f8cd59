#include "handcentric/props/checks/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"

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

// Fisher-Yates; each 64-bit draw gives two indices (32 bits each, multiply-shift into [0, i],
// bias below 2^-23 for samples under 512 rows): the shuffle is the permutation tests' hot loop,
// and it gives the same bits on every platform (std::uniform_int_distribution need not).
void shuffle(std::vector<Eigen::Index>& order, std::mt19937_64& rng) {
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
}

// The p-value of a permutation test: `permutations` shuffles of `order` (from mt19937_64(seed)),
// counting those where exceeds(order) (the permuted statistic is at least the observed one).
// Besag & Clifford (1991): with stop_above > 0, once the p-value cannot fall below stop_above,
// stop and report the sequential estimate (1 + at_least) / (1 + permutations done).
template <class Exceeds>
double permutation_p_value(std::vector<Eigen::Index>& order, int permutations, std::uint64_t seed,
                           double stop_above, const Exceeds& exceeds) {
  std::mt19937_64 rng(seed);
  int at_least = 0;
  for (int b = 0; b < permutations; ++b) {
    shuffle(order, rng);
    if (exceeds(order)) ++at_least;
    if (stop_above > 0.0 && (1.0 + at_least) / (1.0 + permutations) >= stop_above)
      return (1.0 + at_least) / (2.0 + b);
  }
  return (1.0 + at_least) / (1.0 + permutations);
}

std::vector<Eigen::Index> identity_order(Eigen::Index rows) {
  std::vector<Eigen::Index> order(static_cast<std::size_t>(rows));
  std::iota(order.begin(), order.end(), Eigen::Index{0});
  return order;
}

void require_samples(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y) {
  if (x.rows() == 0 || y.rows() == 0 || x.cols() != y.cols()) {
    throw InvalidArgument(
        "energy distance needs two non-empty samples of the same dimension, got " +
        std::to_string(x.rows()) + " x " + std::to_string(x.cols()) + " and " +
        std::to_string(y.rows()) + " x " + std::to_string(y.cols()));
  }
}

void require_permutations(int permutations) {
  if (permutations < 1)
    throw InvalidArgument("a permutation test needs at least 1 permutation, got " +
                          std::to_string(permutations));
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

double sample_sd(const Eigen::VectorXd& v) {
  return std::sqrt((v.array() - v.mean()).square().sum() / static_cast<double>(v.size() - 1));
}

// What scale_test permutes: per coordinate with spread, the absolute deviations z from the
// pooled median (a function of the pooled sample that treats its rows alike, so equal laws
// leave the rows exchangeable), one column of Z each.
struct Deviations {
  std::vector<Eigen::Index> columns;  // the coordinates kept
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> Z;
  std::vector<double> scale;  // sd of z times sqrt(1/n + 1/m): the sd of the mean difference
};

Deviations deviations_from_medians(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y,
                                   double tolerance) {
  const Eigen::Index n = x.rows(), m = y.rows(), N = n + m;
  Deviations out;
  std::vector<Eigen::VectorXd> deviations;
  for (Eigen::Index j = 0; j < x.cols(); ++j) {
    Eigen::VectorXd w(N);
    w << x.col(j), y.col(j);
    const double mean = w.mean();
    if (!(std::sqrt((w.array() - mean).square().sum() / static_cast<double>(N - 1)) > tolerance))
      continue;
    std::vector<double> sorted(w.data(), w.data() + N);
    const auto middle = sorted.begin() + N / 2;
    std::nth_element(sorted.begin(), middle, sorted.end());
    double median = *middle;
    if (N % 2 == 0) median = 0.5 * (median + *std::max_element(sorted.begin(), middle));
    const Eigen::VectorXd z = (w.array() - median).abs().matrix();
    const double z_mean = z.mean();
    const double z_sd = std::sqrt((z.array() - z_mean).square().sum() / static_cast<double>(N - 1));
    if (!(z_sd > 0.0)) continue;
    out.columns.push_back(j);
    deviations.push_back(z);
    out.scale.push_back(z_sd *
                        std::sqrt(1.0 / static_cast<double>(n) + 1.0 / static_cast<double>(m)));
  }
  out.Z.resize(N, static_cast<Eigen::Index>(out.columns.size()));
  for (Eigen::Index c = 0; c < out.Z.cols(); ++c)
    out.Z.col(c) = deviations[static_cast<std::size_t>(c)];
  return out;
}

}  // namespace

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
  return split_energy(pooled_distances(x, y), identity_order(x.rows() + y.rows()), x.rows());
}

TwoSampleResult energy_test(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y, int permutations,
                            std::uint64_t seed, double stop_above) {
  require_samples(x, y);
  require_permutations(permutations);
  const Eigen::MatrixXd D = pooled_distances(x, y);
  const Eigen::Index n = x.rows();
  std::vector<Eigen::Index> order = identity_order(x.rows() + y.rows());
  const bool equal = x.rows() == y.rows();
  const double total = 0.5 * D.sum();
  TwoSampleResult result;
  result.energy_distance = split_energy(D, order, n);
  // A relative slack: a split that equals the observed one up to rounding counts as >=.
  const double threshold = result.energy_distance - 1e-12 * std::abs(result.energy_distance);
  result.p_value = permutation_p_value(order, permutations, seed, stop_above, [&](const auto& o) {
    return (equal ? split_energy_equal(D, o, n, total) : split_energy(D, o, n)) >= threshold;
  });
  return result;
}

int permutations_for(double alpha_per_case) {
  // p can be as small as 1 / (B + 1): ask for B + 1 >= 2 / alpha.
  return std::max(99, static_cast<int>(std::ceil(2.0 / alpha_per_case)) - 1);
}

ScaleTestResult scale_test(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y, int permutations,
                           std::uint64_t seed, double stop_above, double tolerance) {
  require_samples(x, y);
  require_permutations(permutations);
  const Eigen::Index n = x.rows(), m = y.rows(), N = n + m;
  const Deviations deviations = deviations_from_medians(x, y, tolerance);
  ScaleTestResult result;
  const Eigen::Index k = deviations.Z.cols();
  if (k == 0) return result;
  const Eigen::RowVectorXd total = deviations.Z.colwise().sum();
  Eigen::RowVectorXd sum(k);
  // The largest standardized |mean of z over the first n rows of `order` - over the others|.
  auto statistic = [&](const std::vector<Eigen::Index>& order, Eigen::Index* where) {
    sum.setZero();
    for (Eigen::Index a = 0; a < n; ++a)
      sum.noalias() += deviations.Z.row(order[static_cast<std::size_t>(a)]);
    double largest = -1.0;
    for (Eigen::Index c = 0; c < k; ++c) {
      const double gap =
          std::abs(sum(c) / static_cast<double>(n) - (total(c) - sum(c)) / static_cast<double>(m)) /
          deviations.scale[static_cast<std::size_t>(c)];
      if (gap > largest) {
        largest = gap;
        if (where != nullptr) *where = c;
      }
    }
    return largest;
  };
  std::vector<Eigen::Index> order = identity_order(N);
  Eigen::Index where = 0;
  result.statistic = statistic(order, &where);
  result.coordinate = deviations.columns[static_cast<std::size_t>(where)];
  if (n > 1 && m > 1)
    result.sd_ratio = sample_sd(y.col(result.coordinate)) / sample_sd(x.col(result.coordinate));
  const double threshold = result.statistic - 1e-12 * result.statistic;
  result.p_value = permutation_p_value(order, permutations, seed, stop_above, [&](const auto& o) {
    return statistic(o, nullptr) >= threshold;
  });
  return result;
}

int scale_test_permutations(double alpha) {
  if (!(alpha > 0.0 && alpha < 1.0))
    throw InvalidArgument("scale_test_permutations needs 0 < alpha < 1, got " +
                          format_number(alpha));
  return permutations_for(alpha);
}

double permutation_level(double alpha, int permutations) {
  const double total = permutations + 1.0;
  return std::max(0.0, std::ceil(alpha * total) - 1.0) / total;
}

}  // namespace handcentric::props
