#include "handcentric/policy/gaussian.hpp"

#include <cmath>
#include <numbers>

#include "handcentric/core/sampling.hpp"

namespace handcentric::policy {

void fill_standard_normal(std::mt19937_64& rng, Eigen::Ref<Eigen::MatrixXf> out) {
  // Ref<MatrixXf> has an inner stride of 1 but may have an outer stride: walk column by column.
  float spare = 0.0f;
  bool have_spare = false;
  for (Eigen::Index j = 0; j < out.cols(); ++j) {
    for (Eigen::Index i = 0; i < out.rows(); ++i) {
      if (have_spare) {
        out(i, j) = static_cast<float>(spare);
        have_spare = false;
        continue;
      }
      // Box-Muller in float: the noise is float anyway, and float log / sin / cos cost a
      // third of the double ones (this loop was 8% of a training step).
      const float u1 = static_cast<float>(1.0 - uniform01(rng));  // in (0, 1]: log is finite
      const float u2 = static_cast<float>(uniform01(rng));
      const float radius = std::sqrt(-2.0f * std::log(u1));
      const float angle = 2.0f * std::numbers::pi_v<float> * u2;
      out(i, j) = radius * std::cos(angle);
      spare = radius * std::sin(angle);
      have_spare = true;
    }
  }
}

}  // namespace handcentric::policy
