#include "handcentric/props/tolerance.hpp"

#include <algorithm>

namespace handcentric::props {

double length_scale(const Scene& scene) {
  double scale = 0.0;
  for (const auto& T : scene.world_T_hand_history) scale = std::max(scale, T.translation().norm());
  for (const auto& T : scene.world_T_hand_chunk) scale = std::max(scale, T.translation().norm());
  for (const auto& x : scene.world_points) scale = std::max(scale, x.norm());
  for (const auto& x : scene.hand_points) scale = std::max(scale, x.norm());
  for (const auto& named : scene.extra_poses)
    scale = std::max(scale, named.second.translation().norm());
  return scale;
}

double pointwise_tolerance(const Scene& scene, const Scene& moved, double relative) {
  return relative * (1.0 + std::max(length_scale(scene), length_scale(moved)));
}

double distance_from_identity(const RigidTransform& g, const Scene& scene) {
  return g.rotation().angle() + g.translation().norm() / (1.0 + length_scale(scene));
}

bool near_identity(const RigidTransform& g, const Scene& scene) {
  return distance_from_identity(g, scene) < kNearIdentity;
}

}  // namespace handcentric::props
