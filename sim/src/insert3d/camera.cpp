#include "handcentric/sim/insert3d/camera.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include "handcentric/core/errors.hpp"

namespace handcentric::sim::insert3d {

RigidTransform DepthCamera::default_mount() {
  const double a = 10.0 * std::numbers::pi / 180.0;
  Eigen::Matrix3d hand_R_camera;
  // columns: camera x (the hand's +y), camera y, camera z (down the blade, turned toward it)
  hand_R_camera.col(0) = Eigen::Vector3d(0.0, 1.0, 0.0);
  hand_R_camera.col(1) = Eigen::Vector3d(std::cos(a), 0.0, -std::sin(a));
  hand_R_camera.col(2) = Eigen::Vector3d(-std::sin(a), 0.0, -std::cos(a));
  return RigidTransform(Rotation::from_matrix(hand_R_camera), Eigen::Vector3d(3.0, 0.0, -1.0));
}

std::vector<DepthCamera> hand_camera_rig(const DepthCamera& first, int count) {
  first.validate();
  if (count != 1 && count != 2) {
    throw InvalidArgument("a hand camera rig of " + std::to_string(count) +
                          " cameras: use 1 (the task's camera) or 2 (and its mirror about the "
                          "blade)");
  }
  std::vector<DepthCamera> rig{first};
  if (count == 2) {
    DepthCamera second = first;
    // Half a turn about the hand's z: (x, y, z) -> (-x, -y, z); the blade is symmetric under it.
    const RigidTransform hand_T_turned(
        Rotation::from_matrix(Eigen::Vector3d(-1.0, -1.0, 1.0).asDiagonal().toDenseMatrix()),
        Eigen::Vector3d::Zero());
    second.hand_T_camera = hand_T_turned * first.hand_T_camera;
    rig.push_back(second);
  }
  return rig;
}

std::vector<Solid> task_solids_in_hand(const BladeSlotGeometry& geometry,
                                       const RigidTransform& hand_T_slot) {
  geometry.validate();
  const auto box_solid = [](const RigidTransform& hand_T_frame, const Box3& frame_box,
                            const Eigen::Vector3d& albedo) {
    return Solid::box(hand_T_frame * RigidTransform::from_translation(frame_box.centre()),
                      0.5 * frame_box.size(), albedo);
  };
  std::vector<Solid> solids;
  for (const Box3& wall : geometry.slot_walls())
    solids.push_back(box_solid(hand_T_slot, wall, Eigen::Vector3d(0.55, 0.55, 0.6)));
  solids.push_back(box_solid(RigidTransform::identity(), geometry.blade_in_hand(),
                             Eigen::Vector3d(0.3, 0.45, 0.9)));
  return solids;
}

CameraImage render_depth(const BladeSlotGeometry& geometry, const DepthCamera& camera,
                         const RigidTransform& hand_T_slot) {
  camera.validate();
  return render(task_solids_in_hand(geometry, hand_T_slot), camera, camera.hand_T_camera);
}

CameraImage render_depth(const BladeSlotGeometry& geometry, const DepthCamera& camera,
                         const RigidTransform& world_T_hand, const RigidTransform& world_T_slot) {
  return render_depth(geometry, camera, world_T_hand.inverse_compose(world_T_slot));
}

std::array<Eigen::Vector3d, 4> opening_corners_in_hand(const BladeSlotGeometry& geometry,
                                                       const RigidTransform& world_T_hand,
                                                       const RigidTransform& world_T_slot) {
  const RigidTransform hand_T_slot = world_T_hand.inverse_compose(world_T_slot);
  std::array<Eigen::Vector3d, 4> corners = geometry.opening_corners();
  for (Eigen::Vector3d& corner : corners) corner = hand_T_slot * corner;
  return corners;
}

}  // namespace handcentric::sim::insert3d
