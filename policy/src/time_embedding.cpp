#include "handcentric/policy/time_embedding.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "handcentric/core/errors.hpp"

namespace handcentric::policy {

int time_feature_count(int dimension) {
  return dimension == 0 ? 1 : dimension;
}

void time_features(double t, int dimension, Eigen::Ref<Eigen::VectorXf> out) {
  if (out.size() != time_feature_count(dimension)) {
    throw InvalidArgument("time_features: output of length " + std::to_string(out.size()) +
                          ", expected " + std::to_string(time_feature_count(dimension)));
  }
  if (dimension == 0) {
    out[0] = static_cast<float>(t);
    return;
  }
  const int m = dimension / 2;
  for (int i = 0; i < m; ++i) {
    const double w = std::exp2(10.0 * i / std::max(m - 1, 1));
    out[2 * i] = static_cast<float>(std::sin(w * t));
    out[2 * i + 1] = static_cast<float>(std::cos(w * t));
  }
}

}  // namespace handcentric::policy
