#include "handcentric/policy/weight_average.hpp"

#include <algorithm>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"

namespace handcentric::policy {

WeightAverage::WeightAverage(double decay) : decay_(decay) {
  if (!(decay >= 0.0 && decay < 1.0)) {
    throw InvalidArgument("weight average decay " + format_number(decay) +
                          ": use a value in [0, 1) (0.999 is usual; 0 turns it off)");
  }
}

void WeightAverage::update(const Eigen::VectorXf& parameters) {
  if (!active()) return;
  ++updates_;
  if (updates_ == 1) {
    average_ = parameters;
    return;
  }
  const double t = static_cast<double>(updates_);
  const float d = static_cast<float>(std::min(decay_, (1.0 + t) / (10.0 + t)));
  average_ = d * average_ + (1.0f - d) * parameters;
}

}  // namespace handcentric::policy
