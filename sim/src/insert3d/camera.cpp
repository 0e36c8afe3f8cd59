#include "handcentric/sim/insert3d/camera.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"

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

void DepthCamera::validate() const {
  if (width < 1 || width > 4096 || height < 1 || height > 4096) {
    throw InvalidArgument("depth camera size must be 1..4096 pixels each way, got " +
                          std::to_string(width) + " x " + std::to_string(height) +
                          "; e.g. 32 x 24");
  }
  if (!std::isfinite(horizontal_fov_deg) || horizontal_fov_deg <= 0.0 ||
      horizontal_fov_deg >= 170.0) {
    throw InvalidArgument("depth camera horizontal field of view must be in (0, 170) deg, got " +
                          format_number(horizontal_fov_deg) + "; e.g. 70");
  }
  if (!std::isfinite(max_range) || max_range <= 0.0) {
    throw InvalidArgument("depth camera max_range must be a positive number of cm, got " +
                          format_number(max_range) + "; e.g. 60");
  }
}

double DepthCamera::focal_length() const {
  return 0.5 * width / std::tan(0.5 * horizontal_fov_deg * std::numbers::pi / 180.0);
}

double ray_box_hit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                   const Box3& box) {
  double t_near = 0.0;
  double t_far = std::numeric_limits<double>::infinity();
  for (int axis = 0; axis < 3; ++axis) {
    if (direction(axis) == 0.0) {
      if (origin(axis) < box.min(axis) || origin(axis) > box.max(axis)) return -1.0;
      continue;
    }
    double t0 = (box.min(axis) - origin(axis)) / direction(axis);
    double t1 = (box.max(axis) - origin(axis)) / direction(axis);
    if (t0 > t1) std::swap(t0, t1);
    t_near = std::max(t_near, t0);
    t_far = std::min(t_far, t1);
    if (t_near > t_far) return -1.0;
  }
  return t_near;
}

DepthImage render_depth(const BladeSlotGeometry& geometry, const DepthCamera& camera,
                        const RigidTransform& hand_T_slot) {
  geometry.validate();
  camera.validate();
  // Each box is hit in its own frame: the block's in the slot frame, the blade in the hand frame.
  const RigidTransform slot_T_camera = hand_T_slot.inverse_compose(camera.hand_T_camera);
  const RigidTransform& hand_T_camera = camera.hand_T_camera;
  const auto walls = geometry.slot_walls();
  const Box3 blade = geometry.blade_in_hand();
  const double f = camera.focal_length();
  DepthImage image{camera.width, camera.height, {}};
  image.values.resize(static_cast<std::size_t>(camera.width) *
                      static_cast<std::size_t>(camera.height));
  for (int row = 0; row < camera.height; ++row) {
    for (int col = 0; col < camera.width; ++col) {
      const Eigen::Vector3d camera_ray((col + 0.5 - 0.5 * camera.width) / f,
                                       (row + 0.5 - 0.5 * camera.height) / f, 1.0);
      double depth = camera.max_range;
      const auto nearest = [&depth](double t) {
        if (t >= 0.0) depth = std::min(depth, t);
      };
      const Eigen::Vector3d slot_ray = slot_T_camera.rotation() * camera_ray;
      for (const Box3& wall : walls)
        nearest(ray_box_hit(slot_T_camera.translation(), slot_ray, wall));
      nearest(
          ray_box_hit(hand_T_camera.translation(), hand_T_camera.rotation() * camera_ray, blade));
      image.values[static_cast<std::size_t>(row * camera.width + col)] = depth;
    }
  }
  return image;
}

DepthImage render_depth(const BladeSlotGeometry& geometry, const DepthCamera& camera,
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
