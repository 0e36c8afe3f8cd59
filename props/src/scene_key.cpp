#include "handcentric/props/scene_key.hpp"

#include <cstdint>

namespace handcentric::props {
namespace {

void append(std::string& key, const RigidTransform& T) {
  key.append(reinterpret_cast<const char*>(T.rotation().matrix().data()), 9 * sizeof(double));
  key.append(reinterpret_cast<const char*>(T.translation().data()), 3 * sizeof(double));
}

void append_count(std::string& key, std::size_t n) {
  key.append(reinterpret_cast<const char*>(&n), sizeof(n));
}

}  // namespace

namespace detail {

std::string scene_key(const Scene& scene, bool with_chunk) {
  std::string key;
  key.reserve(96 * (scene.world_T_hand_history.size() + scene.world_T_hand_chunk.size()) + 64);
  append_count(key, scene.world_T_hand_history.size());
  for (const RigidTransform& T : scene.world_T_hand_history) append(key, T);
  append_count(key, with_chunk ? scene.world_T_hand_chunk.size() : 0);
  if (with_chunk)
    for (const RigidTransform& T : scene.world_T_hand_chunk) append(key, T);
  for (const auto* points : {&scene.hand_points, &scene.world_points}) {
    append_count(key, points->size());
    for (const Eigen::Vector3d& q : *points)
      key.append(reinterpret_cast<const char*>(q.data()), 3 * sizeof(double));
  }
  for (const auto& [name, T] : scene.extra_poses) append(key, T);
  for (const auto& [name, x] : scene.scalars)
    key.append(reinterpret_cast<const char*>(&x), sizeof(x));
  // Held arrays are shared and never changed: the same array is the same object.
  for (const auto& [name, array] : scene.held) {
    const HeldArray* address = array.get();
    key.append(reinterpret_cast<const char*>(&address), sizeof(address));
  }
  return key;
}

std::string shape_key(const Scene& scene, bool with_chunk) {
  std::string key;
  append_count(key, scene.world_T_hand_history.size());
  append_count(key, with_chunk ? scene.world_T_hand_chunk.size() : 0);
  append_count(key, scene.hand_points.size());
  append_count(key, scene.world_points.size());
  // Held arrays stack into one array per name: their shapes must agree within a batch.
  for (const auto& [name, array] : scene.held) {
    append_count(key, array->shape.size());
    for (const std::int64_t size : array->shape) append_count(key, static_cast<std::size_t>(size));
    key += array->float32 ? 'f' : 'd';
  }
  return key;
}

}  // namespace detail
}  // namespace handcentric::props
