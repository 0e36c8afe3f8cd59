// Demo files of the 2D task (the shared format: demo_file.hpp, docs/SIM.md) and training scenes.
#include "handcentric/sim/demos.hpp"

#include "demo_file.hpp"

namespace handcentric::sim {
namespace {

const detail::DemoFileTask kPeg2d{"peg2d", "world_T_hole", true, "clearance"};

}  // namespace

void save_demos(const std::string& path, const std::vector<Demo>& demos, const PegHoleGeometry& geometry) {
  geometry.validate();
  std::vector<detail::DemoRecord> records;
  records.reserve(demos.size());
  for (const Demo& demo : demos) records.push_back({demo.world_T_hole, demo.world_T_hand});
  detail::save_demo_records(path, kPeg2d, geometry.clearance, records);
}

std::vector<Demo> load_demos(const std::string& path, const DemoFileLimits& limits) {
  std::vector<Demo> demos;
  for (detail::DemoRecord& record : detail::load_demo_records(path, kPeg2d, limits)) {
    demos.push_back({record.world_T_object, std::move(record.world_T_hand)});
  }
  return demos;
}

std::vector<Eigen::Vector3d> eye_in_hand_points(const RigidTransform& world_T_hole,
                                                const RigidTransform& world_T_hand,
                                                const PegHoleGeometry& geometry) {
  const RigidTransform hand_T_hole = world_T_hand.inverse_compose(world_T_hole);
  std::vector<Eigen::Vector3d> points;
  for (const Eigen::Vector3d& hole_p_corner : geometry.opening_corners()) points.push_back(hand_T_hole * hole_p_corner);
  return points;
}

std::vector<Scene> training_scenes(const Demo& demo, int H, int K, const PegHoleGeometry& geometry) {
  return detail::demo_training_scenes(demo.world_T_hand, H, K, [&](const RigidTransform& world_T_hand) {
    return eye_in_hand_points(demo.world_T_hole, world_T_hand, geometry);
  });
}

std::vector<Scene> training_scenes(const std::vector<Demo>& demos, int H, int K, int max_demos,
                                   const PegHoleGeometry& geometry) {
  return detail::demos_training_scenes(demos, max_demos, [&](const Demo& demo) { return training_scenes(demo, H, K, geometry); });
}

}  // namespace handcentric::sim
