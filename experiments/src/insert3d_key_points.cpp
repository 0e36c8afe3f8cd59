#include "handcentric/experiments/insert3d_key_points.hpp"

#include "handcentric/core/errors.hpp"
#include "handcentric/sim/insert3d/geometry.hpp"
#include "handcentric/sim/insert3d/rollout.hpp"

namespace handcentric::experiments {

Scene with_slot_key_points(const Scene& observation) {
  if (observation.hand_points.size() != 4) {
    throw InvalidScene(
        "the 3D policy input starts from the 4 opening corners in the hand frame, got " +
        std::to_string(observation.hand_points.size()) + " hand points");
  }
  const sim::insert3d::BladeSlotGeometry geometry;
  const RigidTransform hand_T_slot =
      sim::insert3d::hand_T_slot_from_corners(observation.hand_points);
  const double outer_x = geometry.inner_half_x() + sim::insert3d::kSlotWallThickness;
  const double outer_y = geometry.inner_half_y() + sim::insert3d::kSlotWallThickness;
  const std::array<Eigen::Vector3d, kSlotKeyPoints> slot_points = {
      Eigen::Vector3d(-outer_x, -outer_y, 0.0), Eigen::Vector3d(outer_x, -outer_y, 0.0),
      Eigen::Vector3d(outer_x, outer_y, 0.0), Eigen::Vector3d(-outer_x, outer_y, 0.0),
      Eigen::Vector3d(0.0, 0.0, -sim::insert3d::kSlotDepth)};
  Scene input = observation;
  for (const Eigen::Vector3d& slot_point : slot_points)
    input.hand_points.push_back(hand_T_slot * slot_point);
  return input;
}

std::vector<Scene> with_slot_key_points(const std::vector<Scene>& scenes) {
  std::vector<Scene> inputs;
  inputs.reserve(scenes.size());
  for (const Scene& scene : scenes) inputs.push_back(with_slot_key_points(scene));
  return inputs;
}

}  // namespace handcentric::experiments
