#include "handcentric/experiments/wilson.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "handcentric/core/errors.hpp"

namespace handcentric::experiments {

Interval wilson_interval(int successes, int trials, double z) {
  if (trials < 1 || successes < 0 || successes > trials) {
    throw InvalidArgument("wilson_interval: " + std::to_string(successes) + " successes in " +
                          std::to_string(trials) +
                          " trials: need trials >= 1 and 0 <= successes <= trials");
  }
  const double n = trials, p = successes / n, z2 = z * z;
  const double denominator = 1.0 + z2 / n;
  const double centre = (p + z2 / (2.0 * n)) / denominator;
  const double half = z * std::sqrt(p * (1.0 - p) / n + z2 / (4.0 * n * n)) / denominator;
  return {std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

}  // namespace handcentric::experiments
