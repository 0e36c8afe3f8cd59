#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <mutex>
#include <random>
#include <string>
#include <tuple>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/props/checks/statistics.hpp"
#include "special_functions.hpp"

namespace handcentric::props {
namespace {

constexpr double kPower = 0.9;  // the power every detectable figure is stated at

void require_power_arguments(const char* what, Eigen::Index dimension, int samples, double alpha) {
  if (dimension < 1 || samples < 2 || !(alpha > 0.0 && alpha < 1.0)) {
    throw InvalidArgument(
        std::string(what) + " needs dimension >= 1, samples >= 2 and 0 < alpha < 1, got " +
        std::to_string(dimension) + ", " + std::to_string(samples) + ", " + format_number(alpha));
  }
}

// simulated_energy_test_detectable_shift at the audit's defaults (32 draws, level
// 0.01 / 10 cases / 3 tests) for the dimensions 1, 2, 4, ..., 1024: each costs 5 to 15 s to
// simulate (every rejection runs all 5999 permutations), so a check would pay that on its first
// "yes". tests/props checks that the table is the simulation's output.
constexpr std::array<double, 11> kDefaultDetectableShift = {1.4375,  1.421875, 1.546875, 1.671875,
                                                            1.75,    1.984375, 2.28125,  2.5625,
                                                            2.90625, 3.3125,   3.96875};

}  // namespace

double simulated_energy_test_detectable_shift(Eigen::Index dimension, int samples, double alpha) {
  require_power_arguments("energy_test_detectable_shift", dimension, samples, alpha);
  Eigen::Index rounded = 1;
  while (rounded < dimension) rounded *= 2;
  constexpr int kRepetitions = 100;
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
  return high;
}

double energy_test_detectable_shift(Eigen::Index dimension, int samples, double alpha) {
  if (dimension < 1 || samples < 2 || !(alpha > 0.0 && alpha < 1.0))
    return simulated_energy_test_detectable_shift(dimension, samples, alpha);  // it throws
  Eigen::Index rounded = 1;
  std::size_t power_of_two = 0;
  for (; rounded < dimension; rounded *= 2) ++power_of_two;
  if (samples == 32 && alpha == kDefaultTestLevel && power_of_two < kDefaultDetectableShift.size())
    return kDefaultDetectableShift[power_of_two];
  static std::mutex mutex;
  static std::map<std::tuple<Eigen::Index, int, double>, double> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  const auto key = std::make_tuple(rounded, samples, alpha);
  if (const auto hit = cache.find(key); hit != cache.end()) return hit->second;
  const double shift = simulated_energy_test_detectable_shift(rounded, samples, alpha);
  cache.emplace(key, shift);
  return shift;
}

double scale_test_power(double ratio, Eigen::Index dimension, int samples, double alpha) {
  require_power_arguments("scale_test_power", dimension, samples, alpha);
  if (!(ratio > 0.0) || !std::isfinite(ratio))
    throw InvalidArgument("scale_test_power needs a positive ratio, got " + format_number(ratio));
  // |X| for X ~ N(0, 1) has mean c and variance 1 - c^2; |X| for N(0, r^2) has r times those.
  // The statistic is (mean_x z - mean_y z) / (sd_pooled(z) sqrt(2 / n)), sd_pooled that of the
  // two halves together (the permutation-invariant scale); by the central limit theorem it is
  // normal with the mean and sd below.
  const double r = std::max(ratio, 1.0 / ratio);
  const double c = std::sqrt(2.0 / std::acos(-1.0));
  const double variance_x = 1.0 - c * c, variance_y = r * r * variance_x;
  const double half_gap = 0.5 * c * (r - 1.0);
  const double pooled = 0.5 * (variance_x + variance_y) + half_gap * half_gap;
  const double mean = c * (r - 1.0) / std::sqrt(pooled * 2.0 / static_cast<double>(samples));
  const double sd = std::sqrt((variance_x + variance_y) / (2.0 * pooled));
  const double critical =
      detail::normal_upper_quantile(alpha / (2.0 * static_cast<double>(dimension)));  // Bonferroni
  return detail::normal_upper_tail((critical - mean) / sd) +
         detail::normal_upper_tail((critical + mean) / sd);
}

double scale_test_detectable_ratio(Eigen::Index dimension, int samples, double alpha) {
  require_power_arguments("scale_test_detectable_ratio", dimension, samples, alpha);
  double low = 1.0, high = 2.0;
  while (scale_test_power(high, dimension, samples, alpha) < kPower && high < 1e12) {
    low = high;
    high *= 2.0;
  }
  for (int step = 0; step < 60 && high - low > 1e-6; ++step) {
    const double middle = 0.5 * (low + high);
    (scale_test_power(middle, dimension, samples, alpha) >= kPower ? high : low) = middle;
  }
  return high;
}

int samples_for_scale_ratio(Eigen::Index dimension, double alpha, double ratio) {
  require_power_arguments("samples_for_scale_ratio", dimension, 2, alpha);
  if (!(ratio > 1.0) || !std::isfinite(ratio))
    throw InvalidArgument("samples_for_scale_ratio needs a ratio > 1, got " + format_number(ratio));
  auto enough = [&](int samples) {
    return scale_test_power(ratio, dimension, samples, alpha) >= kPower;
  };
  int low = 1, high = 2;  // enough(low) is false (1 row has no spread), enough(high) is sought
  while (!enough(high)) {
    low = high;
    if (high > (1 << 24)) return high;  // a ratio this close to 1 is out of reach anyway
    high *= 2;
  }
  while (high - low > 1) {
    const int middle = low + (high - low) / 2;
    (enough(middle) ? high : low) = middle;
  }
  return high;
}

}  // namespace handcentric::props
