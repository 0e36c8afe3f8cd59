#include "handcentric/props/checks/affine_law.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/props/prefetch.hpp"

namespace handcentric::props {
namespace {

using NoiseMap = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;

// Marks coordinate j not affine when `deviation` (what an affine map makes zero) exceeds
// `bound` there (or is NaN).
void keep_where(std::vector<bool>& affine, const Eigen::VectorXd& deviation, double bound) {
  for (Eigen::Index j = 0; j < deviation.size(); ++j) {
    if (!(std::abs(deviation(j)) <= bound)) affine[static_cast<std::size_t>(j)] = false;
  }
}

// The noise map J of out.law (column j: f(e_j) - f(0)), then mean + J eps verified at each of
// `checked`, per coordinate. False when f changes length.
bool probe_noise_map(const NoiseMap& f, Eigen::Index n, const std::vector<Eigen::VectorXd>& checked,
                     double tolerance, PartlyAffineLaw& out) {
  GaussianLaw& law = out.law;
  const Eigen::Index width = law.mean.size();
  ask_ahead(
      [&] {
        std::vector<Eigen::VectorXd> probes = checked;
        for (Eigen::Index j = 0; j < n; ++j) probes.push_back(Eigen::VectorXd::Unit(n, j));
        return probes;
      },
      f);
  Eigen::VectorXd eps = Eigen::VectorXd::Zero(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    eps(j) = 1.0;
    const Eigen::VectorXd column = f(eps);
    eps(j) = 0.0;
    if (column.size() != width) return false;
    law.noise_map.col(j) = column - law.mean;
  }
  // Affine maps agree with mean + J eps everywhere; verify it where nothing was probed.
  for (const Eigen::VectorXd& at : checked) {
    const Eigen::VectorXd value = f(at);
    if (value.size() != width) return false;
    const Eigen::VectorXd predicted = law.mean + law.noise_map * at;
    keep_where(out.affine, value - predicted, tolerance);
  }
  return true;
}

}  // namespace

bool PartlyAffineLaw::all_affine() const {
  return std::all_of(affine.begin(), affine.end(), [](bool a) { return a; });
}

std::optional<PartlyAffineLaw> partly_affine_law(const NoiseMap& f, Eigen::Index n,
                                                 double tolerance, std::uint64_t seed, int checks) {
  if (n < 0) {
    throw InvalidArgument("affine_law needs a noise dimension >= 0, got " + std::to_string(n));
  }
  PartlyAffineLaw out;
  GaussianLaw& law = out.law;
  const Eigen::VectorXd eps = Eigen::VectorXd::Zero(n);
  std::mt19937_64 rng(seed);
  auto normals = [&rng, n] {
    Eigen::VectorXd v(n);
    for (Eigen::Index j = 0; j < n; ++j) v(j) = standard_normal(rng);
    return v;
  };
  // Every input of a phase is drawn before the first is evaluated, so that a batched map can
  // answer them together (prefetch.hpp); the draws are in the same order either way.
  const Eigen::VectorXd u = normals(), v = normals();
  std::vector<Eigen::VectorXd> checked;
  for (int c = 0; c < checks; ++c) checked.push_back(normals());
  ask_ahead([&] { return std::vector<Eigen::VectorXd>{eps, u, v, u + v}; }, f);
  law.mean = f(eps);
  const Eigen::Index width = law.mean.size();
  out.affine.assign(static_cast<std::size_t>(width), true);
  // A cheap necessary test first (4 evaluations, where probing takes n + 1): an affine map is
  // additive about f(0). Most maps that are not affine (a sampler through a network) fail it in
  // every coordinate, and then nothing is probed.
  {
    const Eigen::VectorXd fu = f(u), fv = f(v), fuv = f(u + v);
    if (fu.size() != width || fv.size() != width || fuv.size() != width) return std::nullopt;
    keep_where(out.affine, fuv - fu - fv + law.mean, 2.0 * tolerance);
  }
  law.noise_map = Eigen::MatrixXd::Zero(width, n);
  if (width > 0 && std::none_of(out.affine.begin(), out.affine.end(), [](bool a) { return a; }))
    return out;
  if (!probe_noise_map(f, n, checked, tolerance, out)) return std::nullopt;
  return out;
}

std::optional<GaussianLaw> affine_law(const NoiseMap& f, Eigen::Index n, double tolerance,
                                      std::uint64_t seed, int checks) {
  std::optional<PartlyAffineLaw> partly = partly_affine_law(f, n, tolerance, seed, checks);
  if (!partly || !partly->all_affine()) return std::nullopt;
  return std::move(partly->law);
}

LawDifference law_difference(const GaussianLaw& a, const GaussianLaw& b) {
  LawDifference difference;
  if (a.mean.size() != b.mean.size() || a.noise_map.rows() != b.noise_map.rows()) {
    difference.mean = difference.covariance = std::numeric_limits<double>::infinity();
    return difference;
  }
  if (a.mean.size() == 0) return difference;
  difference.mean = (a.mean - b.mean).cwiseAbs().maxCoeff<Eigen::PropagateNaN>();
  // The largest |entry| of a covariance J J^T is on its diagonal (|C_ij| <= sqrt(C_ii C_jj) for a
  // positive semi-definite C): the largest squared row norm of J, without the product.
  auto largest_variance = [](const Eigen::MatrixXd& J) {
    return J.cols() == 0 ? 0.0 : J.rowwise().squaredNorm().maxCoeff<Eigen::PropagateNaN>();
  };
  difference.covariance_scale = std::max(1.0, largest_variance(a.noise_map));
  // Equal noise maps give equal covariances, the common case (a rectified flow's J is the same
  // for every scene): no product then.
  if (a.noise_map.cols() == b.noise_map.cols() && a.noise_map == b.noise_map) return difference;
  difference.covariance_scale =
      std::max(difference.covariance_scale, largest_variance(b.noise_map));
  // J_a J_a^T - J_b J_b^T is symmetric: its lower triangle alone (the upper stays 0), by two rank
  // updates, half the work of the two products (maps that differ in rounding come here too).
  const Eigen::Index rows = a.noise_map.rows();
  Eigen::MatrixXd lower = Eigen::MatrixXd::Zero(rows, rows);
  lower.selfadjointView<Eigen::Lower>().rankUpdate(a.noise_map, 1.0);
  lower.selfadjointView<Eigen::Lower>().rankUpdate(b.noise_map, -1.0);
  difference.covariance = lower.cwiseAbs().maxCoeff<Eigen::PropagateNaN>();
  return difference;
}

}  // namespace handcentric::props
