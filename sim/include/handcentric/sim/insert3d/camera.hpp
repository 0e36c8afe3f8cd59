#pragma once
// The hand camera of the 3D task: a small depth image rendered by ray casting from a camera
// fixed to the hand (eye-in-hand, as in "Hand-centric action representations make behavior
// cloning SE(3)-equivariant", Sec. 3.2). The image depends only on where the slot is relative
// to the hand, hand_T_slot, so the image of g * scene is the image of the scene for every g in
// SE(3) (tests/sim checks it to 1e-9, and that a camera fixed in the world fails).
//
// Camera frame (OpenCV's): +z along the optical axis, +x to the right of the image, +y down.
// Pixel (row, col) looks along ((col + 0.5 - W/2) / f, (row + 0.5 - H/2) / f, 1) with
// f = (W/2) / tan(horizontal_fov / 2), so the ray parameter of a hit is its depth (its camera z).
// The rendered objects are the block's five boxes and the blade (which the camera sees at the
// same place in every image); a ray that hits nothing within max_range reads max_range.
#include <vector>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/sim/insert3d/geometry.hpp"

namespace handcentric::sim::insert3d {

struct DepthCamera {
  int width = 32;
  int height = 24;
  double horizontal_fov_deg = 70.0;
  /// Depth (cm) read where a ray hits nothing.
  double max_range = 60.0;
  /// Where the camera sits on the hand.
  RigidTransform hand_T_camera = default_mount();

  /// Beside the blade, 3 cm off its axis along the hand's +x and 1 cm below the hand, looking
  /// down the blade (the hand's -z) and turned 10 deg toward the blade's axis, so it sees the
  /// slot's opening from the approach to full insertion.
  static RigidTransform default_mount();

  /// Throws InvalidArgument naming the value and the fix: sizes outside [1, 4096], a field of
  /// view outside (0, 170) deg, a non-positive or non-finite range.
  void validate() const;

  /// f, the focal length in pixels.
  double focal_length() const;
};

/// A depth image, row-major: depth(row, col) = values[row * width + col].
struct DepthImage {
  int width = 0;
  int height = 0;
  std::vector<double> values;

  double at(int row, int col) const { return values[static_cast<std::size_t>(row * width + col)]; }
};

/// The nearest hit of the ray origin + t direction (t >= 0) with the axis-aligned box, or a
/// negative number when it misses (slab method; a ray starting inside the box hits at t = 0).
double ray_box_hit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                   const Box3& box);

/// The depth image seen by `camera` on the hand at hand_T_slot relative to the slot. Throws
/// InvalidArgument for a bad camera or geometry.
DepthImage render_depth(const BladeSlotGeometry& geometry, const DepthCamera& camera,
                        const RigidTransform& hand_T_slot);

/// The same for a scene in the world: renders hand_T_slot = world_T_hand^-1 world_T_slot.
DepthImage render_depth(const BladeSlotGeometry& geometry, const DepthCamera& camera,
                        const RigidTransform& world_T_hand, const RigidTransform& world_T_slot);

/// The eye-in-hand key points: the slot opening's four corners (BladeSlotGeometry's order) in the
/// hand frame, as the 2D task's two corners.
std::array<Eigen::Vector3d, 4> opening_corners_in_hand(const BladeSlotGeometry& geometry,
                                                       const RigidTransform& world_T_hand,
                                                       const RigidTransform& world_T_slot);

}  // namespace handcentric::sim::insert3d
