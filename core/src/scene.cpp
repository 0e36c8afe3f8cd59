#include "handcentric/core/scene.hpp"

#include <cmath>
#include <string>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"

namespace handcentric {
namespace {

void require_finite_points(const std::vector<Eigen::Vector3d>& points, const char* which) {
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      throw InvalidScene(std::string(which) + " point " + std::to_string(i) +
                         " has a non-finite coordinate: " + format_matrix(points[i]));
    }
  }
}

}  // namespace

void Scene::validate_observation() const {
  if (world_T_hand_history.empty()) {
    throw InvalidScene("scene has no hand pose: the history needs at least T_0 (H >= 0)");
  }
  require_finite_points(world_points, "world");
  require_finite_points(hand_points, "eye-in-hand");
  for (const auto& [name, value] : scalars) {
    if (!std::isfinite(value)) {
      throw InvalidScene("scalar '" + name + "' is not finite: " + format_number(value));
    }
  }
  for (const auto& [name, array] : held) {
    if (!array) throw InvalidScene("held array '" + name + "' is null");
  }
}

void Scene::validate() const {
  validate_observation();
  if (world_T_hand_chunk.empty()) {
    throw InvalidScene("scene has an empty action chunk: K must be at least 1");
  }
}

Scene operator*(const RigidTransform& g, const Scene& scene) {
  Scene moved;
  moved.world_T_hand_history.reserve(scene.world_T_hand_history.size());
  for (const RigidTransform& world_T_hand : scene.world_T_hand_history) {
    moved.world_T_hand_history.push_back(g * world_T_hand);
  }
  moved.world_T_hand_chunk.reserve(scene.world_T_hand_chunk.size());
  for (const RigidTransform& world_T_hand : scene.world_T_hand_chunk) {
    moved.world_T_hand_chunk.push_back(g * world_T_hand);
  }
  moved.world_points.reserve(scene.world_points.size());
  for (const Eigen::Vector3d& point_world : scene.world_points) {
    moved.world_points.push_back(g * point_world);
  }
  moved.hand_points = scene.hand_points;  // eye-in-hand: unchanged (Sec. 3.2)
  moved.extra_poses.reserve(scene.extra_poses.size());
  for (const auto& [name, world_T_other] : scene.extra_poses)
    moved.extra_poses.emplace_back(name, g * world_T_other);
  moved.scalars = scene.scalars;
  moved.held = scene.held;
  return moved;
}

}  // namespace handcentric
