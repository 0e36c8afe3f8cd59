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

namespace {

std::vector<Demo> to_demos(std::vector<detail::DemoRecord> records) {
  std::vector<Demo> demos;
  demos.reserve(records.size());
  for (detail::DemoRecord& record : records) demos.push_back({record.world_T_object, std::move(record.world_T_hand)});
  return demos;
}

}  // namespace

std::vector<Demo> load_demos(const std::string& path, const DemoFileLimits& limits) {
  return to_demos(detail::load_demo_records(path, kPeg2d, limits));
}

std::vector<Demo> parse_demos(const std::string& bytes, const std::string& source, const DemoFileLimits& limits) {
  return to_demos(detail::parse_demo_records(bytes, source, kPeg2d, limits));
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

Demo mirrored_about_hole_axis(const Demo& demo) {
  if (demo.world_T_hand.empty()) throw InvalidArgument("mirrored_about_hole_axis: the demo has no hand pose");
  Demo mirrored;
  mirrored.world_T_hole = demo.world_T_hole;
  mirrored.world_T_hand.reserve(demo.world_T_hand.size());
  for (const RigidTransform& world_T_hand : demo.world_T_hand) {
    const RigidTransform hole_T_hand = demo.world_T_hole.inverse_compose(world_T_hand);
    const Eigen::Matrix3d& R = hole_T_hand.rotation().matrix();
    const Eigen::Vector3d& p = hole_T_hand.translation();
    if (std::abs(p.z()) > 1e-9 || std::abs(R(2, 2) - 1.0) > 1e-9) {
      throw InvalidArgument("mirrored_about_hole_axis: a hand pose is not planar in its hole's frame (z = " +
                            std::to_string(p.z()) + "): only planar demos can be mirrored");
    }
    const double theta = std::atan2(R(1, 0), R(0, 0));
    mirrored.world_T_hand.push_back(demo.world_T_hole * RigidTransform::planar(-theta, -p.x(), p.y()));
  }
  return mirrored;
}

std::vector<Demo> with_mirrored_demos(const std::vector<Demo>& demos) {
  std::vector<Demo> all = demos;
  all.reserve(2 * demos.size());
  for (const Demo& demo : demos) all.push_back(mirrored_about_hole_axis(demo));
  return all;
}

std::vector<Scene> training_scenes(const std::vector<Demo>& demos, int H, int K, int max_demos,
                                   const TrainingData& data, const PegHoleGeometry& geometry) {
  std::vector<Scene> scenes = training_scenes(demos, H, K, max_demos, geometry);
  if (!data.mirror) return scenes;
  const std::size_t used = max_demos == 0 ? demos.size() : static_cast<std::size_t>(max_demos);
  for (std::size_t i = 0; i < used; ++i) {
    for (Scene& scene : training_scenes(mirrored_about_hole_axis(demos[i]), H, K, geometry)) {
      scenes.push_back(std::move(scene));
    }
  }
  return scenes;
}

}  // namespace handcentric::sim
