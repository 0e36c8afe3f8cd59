#pragma once
// The scene options the commands share for --task insert3d, and the refusal of 3D-only options
// on the 2D task: one place for the rules and their messages.
#include <string>

#include "handcentric/core/errors.hpp"
#include "handcentric/sim/insert3d/scenes.hpp"

namespace handcentric::apps {

/// The 3D scene distribution from --dist or --rotate-deg; the 2D-only options are an error.
inline sim::insert3d::SceneDistribution insert3d_distribution(const std::string& dist,
                                                              const std::string& rotate_deg,
                                                              const std::string& hole_angle_deg,
                                                              const std::string& transform) {
  if (!hole_angle_deg.empty() || !transform.empty()) {
    throw InvalidArgument(
        "--hole-angle-deg and --transform are options of the 2D task; with --task insert3d use "
        "--dist train|ood|random-se3 or --rotate-deg RX,RY,RZ");
  }
  return rotate_deg.empty() ? sim::insert3d::SceneDistribution::parse(dist)
                            : sim::insert3d::SceneDistribution::parse_rotate_deg(rotate_deg);
}

/// Throws for --rotate-deg or --dist random-se3 on the 2D task.
inline void refuse_3d_options(const std::string& dist, const std::string& rotate_deg) {
  if (!rotate_deg.empty() || dist == "random-se3") {
    throw InvalidArgument(
        "--rotate-deg and --dist random-se3 are options of the 3D task: add --task insert3d");
  }
}

}  // namespace handcentric::apps
