#include "handcentric/sim/insert3d/demos.hpp"

#include "../demo_file.hpp"
#include "handcentric/sim/insert3d/camera.hpp"

namespace handcentric::sim::insert3d {
namespace {

const detail::DemoFileTask kInsert3d{"insert3d", "world_T_slot", false, "clearance_per_side"};

}  // namespace

void save_demos(const std::string& path, const std::vector<Demo>& demos,
                const BladeSlotGeometry& geometry) {
  geometry.validate();
  std::vector<detail::DemoRecord> records;
  records.reserve(demos.size());
  for (const Demo& demo : demos) records.push_back({demo.world_T_slot, demo.world_T_hand});
  detail::save_demo_records(path, kInsert3d, geometry.clearance_per_side, records);
}

std::vector<Demo> load_demos(const std::string& path, const DemoFileLimits& limits) {
  std::vector<Demo> demos;
  for (detail::DemoRecord& record : detail::load_demo_records(path, kInsert3d, limits)) {
    demos.push_back({record.world_T_object, std::move(record.world_T_hand)});
  }
  return demos;
}

std::vector<Scene> training_scenes(const Demo& demo, int H, int K,
                                   const BladeSlotGeometry& geometry) {
  return detail::demo_training_scenes(
      demo.world_T_hand, H, K, [&](const RigidTransform& world_T_hand) {
        const auto corners = opening_corners_in_hand(geometry, world_T_hand, demo.world_T_slot);
        return std::vector<Eigen::Vector3d>(corners.begin(), corners.end());
      });
}

std::vector<Scene> training_scenes(const std::vector<Demo>& demos, int H, int K, int max_demos,
                                   const BladeSlotGeometry& geometry) {
  return detail::demos_training_scenes(
      demos, max_demos, [&](const Demo& demo) { return training_scenes(demo, H, K, geometry); });
}

}  // namespace handcentric::sim::insert3d
