#include "handcentric/sim/scenes.hpp"

#include <charconv>
#include <cmath>
#include <numbers>
#include <random>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/core/sampling.hpp"
#include "scene_helpers.hpp"

namespace handcentric::sim {
using detail::parse_double;
using detail::radians;
using detail::uniform;

TaskScene operator*(const RigidTransform& g, const TaskScene& scene) {
  return TaskScene{g * scene.world_T_hole, g * scene.world_T_hand_start};
}

SceneDistribution SceneDistribution::train() {
  return SceneDistribution{"train", {{-10.0, 10.0}, {-10.0, 10.0}, {80.0, 100.0}, {-100.0, -80.0}}};
}

SceneDistribution SceneDistribution::ood() {
  return SceneDistribution{"ood", {{170.0, 190.0}}};
}

SceneDistribution SceneDistribution::hole_angle_range(double min_deg, double max_deg) {
  if (!std::isfinite(min_deg) || !std::isfinite(max_deg) || min_deg > max_deg) {
    throw InvalidArgument("hole angle range must be finite with A <= B, got " +
                          format_number(min_deg) + ":" + format_number(max_deg) +
                          "; e.g. --hole-angle-deg -10:10");
  }
  return SceneDistribution{format_number(min_deg) + ":" + format_number(max_deg),
                           {{min_deg, max_deg}}};
}

SceneDistribution SceneDistribution::parse(const std::string& text) {
  if (text == "train") return train();
  if (text == "ood") return ood();
  const auto colon = text.find(':');
  double lo = 0.0;
  double hi = 0.0;
  if (colon == std::string::npos || !parse_double(text.substr(0, colon), lo) ||
      !parse_double(text.substr(colon + 1), hi)) {
    throw InvalidArgument("unknown scene distribution '" + text +
                          "'; use train, ood or a hole-angle range A:B in degrees such as 170:190");
  }
  return hole_angle_range(lo, hi);
}

RigidTransform parse_planar_transform(const std::string& text) {
  Eigen::Vector3d values;
  if (!detail::parse_finite_triple(text, values)) {
    throw InvalidArgument(
        "bad planar transform '" + text +
        "'; expected DEG,X,Y (three finite numbers: degrees about z, then cm), e.g. 90,10,-5");
  }
  return RigidTransform::planar(radians(values(0)), values(1), values(2));
}

std::vector<TaskScene> transform_scenes(const RigidTransform& g,
                                        const std::vector<TaskScene>& scenes) {
  std::vector<TaskScene> moved;
  moved.reserve(scenes.size());
  for (const TaskScene& scene : scenes) moved.push_back(g * scene);
  return moved;
}

std::uint64_t stream_seed(std::uint64_t seed, std::uint64_t index) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ULL * (index + 1);  // splitmix64
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

TaskScene sample_scene(const SceneDistribution& distribution, std::uint64_t seed,
                       std::uint64_t index) {
  if (distribution.hole_angles.empty()) {
    throw InvalidArgument("scene distribution '" + distribution.name + "' has no hole-angle range");
  }
  std::mt19937_64 rng(stream_seed(seed, index));
  // the start relative to the hole first, so it does not depend on the distribution
  const double x = uniform(rng, -kStartMaxAbsX, kStartMaxAbsX);
  const double y = uniform(rng, kStartMinY, kStartMaxY);
  const double angle = radians(uniform(rng, -kStartMaxAbsAngleDeg, kStartMaxAbsAngleDeg));
  const RigidTransform hole_T_hand_start = RigidTransform::planar(angle, x, y);
  const std::size_t pick = static_cast<std::size_t>(rng() % distribution.hole_angles.size());
  const AngleRange& range = distribution.hole_angles[pick];
  const double hole_angle = radians(uniform(rng, range.min_deg, range.max_deg));
  const double half_width = distribution.workspace_half_width;
  if (!std::isfinite(half_width) || half_width <= 0.0) {
    throw InvalidArgument("scene distribution '" + distribution.name +
                          "' has workspace half-width " + format_number(half_width) +
                          " cm; it must be a positive number");
  }
  const double hole_x = uniform(rng, -half_width, half_width);
  const double hole_y = uniform(rng, -half_width, half_width);
  const RigidTransform world_T_hole = RigidTransform::planar(hole_angle, hole_x, hole_y);
  return TaskScene{world_T_hole, world_T_hole * hole_T_hand_start};
}

std::vector<TaskScene> sample_scenes(const SceneDistribution& distribution, int n,
                                     std::uint64_t seed) {
  return detail::sample_n(sample_scene, distribution, n, seed);
}

}  // namespace handcentric::sim
