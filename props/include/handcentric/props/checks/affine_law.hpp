#pragma once
// The law of a map of the noise eps ~ N(0, I) where the map is affine in it: probed at eps = 0
// and the unit vectors, verified at random eps, per output coordinate. Such a law is Gaussian,
// and two Gaussian laws are equal iff their means and covariances are (law_difference): the exact
// half of the in-distribution checks (distribution.hpp).
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

namespace handcentric::props {

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

/// The laws of the coordinates of f that are affine in eps: f_j(eps) = mean_j + J_j eps for the
/// coordinates j with affine[j] (law.noise_map's other rows mean nothing).
struct PartlyAffineLaw {
  GaussianLaw law;
  std::vector<bool> affine;  ///< per output coordinate
  bool all_affine() const;
};

/// affine_law per coordinate: f at eps = 0, then an additivity check per coordinate at two
/// normal draws (a coordinate that fails it is not affine), then, if any coordinate is left,
/// the n unit vectors and `checks` verifications at normal eps, per coordinate, within
/// `tolerance`. The same evaluations and draws as affine_law, which returns a law exactly when
/// every coordinate here is affine. Returns nullopt when f changes length.
std::optional<PartlyAffineLaw> partly_affine_law(
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f, Eigen::Index n,
    double tolerance, std::uint64_t seed, int checks = 2);

}  // namespace handcentric::props
