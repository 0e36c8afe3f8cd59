#pragma once
// Helpers private to sim's sources (not installed): seeded uniform numbers, degrees, the strict
// number parsing of the scene options (the whole text must be the number), scene lists.
#include <Eigen/Core>

#include <charconv>
#include <cmath>
#include <numbers>
#include <random>
#include <cstdint>
#include <string>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/sampling.hpp"

namespace handcentric::sim::detail {

inline double uniform(std::mt19937_64& rng, double lo, double hi) {
  return lo + (hi - lo) * uniform01(rng);
}

inline double radians(double degrees) {
  return degrees * std::numbers::pi / 180.0;
}

/// The whole of `text` as a double (from_chars: no locale, no leading spaces).
inline bool parse_double(const std::string& text, double& value) {
  const char* end = text.data() + text.size();
  const auto result = std::from_chars(text.data(), end, value);
  return result.ec == std::errc() && result.ptr == end;
}

/// "A,B,C": three finite numbers separated by commas, nothing else.
inline bool parse_finite_triple(const std::string& text, Eigen::Vector3d& values) {
  std::size_t begin = 0;
  for (int i = 0; i < 3; ++i) {
    const std::size_t end = i < 2 ? text.find(',', begin) : text.size();
    if (end == std::string::npos || !parse_double(text.substr(begin, end - begin), values(i)) ||
        !std::isfinite(values(i))) {
      return false;
    }
    begin = end + 1;
  }
  return true;
}

/// Scenes 0..n-1 of the stream `seed` drawn by sample(distribution, seed, index). Throws
/// InvalidArgument for n < 0.
template <typename Sample, typename Distribution>
auto sample_n(Sample sample, const Distribution& distribution, int n, std::uint64_t seed) {
  if (n < 0) throw InvalidArgument("number of scenes must be >= 0, got " + std::to_string(n));
  std::vector<decltype(sample(distribution, seed, std::uint64_t{0}))> scenes;
  scenes.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i)
    scenes.push_back(sample(distribution, seed, static_cast<std::uint64_t>(i)));
  return scenes;
}

}  // namespace handcentric::sim::detail
