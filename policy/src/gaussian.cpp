#include "handcentric/policy/gaussian.hpp"

#include <cmath>
#include <numbers>

#include "handcentric/core/sampling.hpp"

namespace handcentric::policy {

void fill_standard_normal(std::mt19937_64& rng, Eigen::Ref<Eigen::MatrixXf> out) {
  // Ref<MatrixXf> has an inner stride of 1 but may have an outer stride: walk column by column.
  double spare = 0.0;
  bool have_spare = false;
  for (Eigen::Index j = 0; j < out.cols(); ++j) {
    for (Eigen::Index i = 0; i < out.rows(); ++i) {
      if (have_spare) {
        out(i, j) = static_cast<float>(spare);
        have_spare = false;
        continue;
      }
      const double u1 = 1.0 - uniform01(rng);  // in (0, 1]: log is finite
      const double u2 = uniform01(rng);
      const double radius = std::sqrt(-2.0 * std::log(u1));
      const double angle = 2.0 * std::numbers::pi * u2;
      out(i, j) = static_cast<float>(radius * std::cos(angle));
      spare = radius * std::sin(angle);
      have_spare = true;
    }
  }
}

}  // namespace handcentric::policy
