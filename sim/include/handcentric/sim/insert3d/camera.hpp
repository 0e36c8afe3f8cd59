#pragma once
// The hand camera of the 3D task: a small depth image rendered by ray casting (core/camera.hpp,
// the camera model the audit renders with too) from a camera fixed to the hand (eye-in-hand, as
// in "Guaranteed SE(3)-Equivariant Control via Hand-Centric Behavior Cloning", Sec. 3.2). The
// image depends only on where the slot is relative to the hand, hand_T_slot, so the image of
// g * scene is the image of the scene for every g in SE(3) (tests/sim checks it to 1e-9, and that
// a camera fixed in the world fails).
//
// The rendered objects are the block's five boxes and the blade (which the camera sees at the
// same place in every image); a ray that hits nothing within max_range (cm) reads max_range.
#include <array>
#include <vector>

#include "handcentric/core/camera.hpp"
#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/sim/insert3d/geometry.hpp"

namespace handcentric::sim::insert3d {

/// The task's hand camera: 32 x 24 pixels, 70 deg across, 60 cm of range, on default_mount().
struct DepthCamera : PinholeCamera {
  DepthCamera() : PinholeCamera{32, 24, 70.0, 60.0} {}

  /// Where the camera sits on the hand.
  RigidTransform hand_T_camera = default_mount();

  /// Beside the blade, 3 cm off its axis along the hand's +x and 1 cm below the hand, looking
  /// down the blade (the hand's -z) and turned 10 deg toward the blade's axis, so it sees the
  /// slot's opening from the approach to full insertion.
  static RigidTransform default_mount();

  /// Throws InvalidArgument naming the value and the fix (PinholeCamera::validate).
  void validate() const { PinholeCamera::validate("depth camera"); }
};

/// The hand camera rig: `count` cameras of `first`'s intrinsics, all fixed to the hand. The first
/// is `first`; a second (count 2) is its mirror about the blade's plane (the hand's y-z plane),
/// turned half a turn about the hand's z axis so that it stays a right-handed camera: 3 cm off
/// the blade on the hand's -x side, it sees the block where the blade hides it from the first
/// (docs/SIM.md, "Image policies"). Both depend on hand-frame points only, so the rig's images
/// are SE(3)-invariant as one camera's are. Throws InvalidArgument for a count other than 1 or 2
/// or a bad camera.
std::vector<DepthCamera> hand_camera_rig(const DepthCamera& first, int count);

/// The block's walls (in the slot frame) and the blade (in the hand frame) as solids in the hand
/// frame, for the hand at hand_T_slot relative to the slot.
std::vector<Solid> task_solids_in_hand(const BladeSlotGeometry& geometry,
                                       const RigidTransform& hand_T_slot);

/// The image seen by `camera` on the hand at hand_T_slot relative to the slot (its depth is what
/// the task's policies and figures read). Throws InvalidArgument for a bad camera or geometry.
CameraImage render_depth(const BladeSlotGeometry& geometry, const DepthCamera& camera,
                         const RigidTransform& hand_T_slot);

/// The same for a scene in the world: renders hand_T_slot = world_T_hand^-1 world_T_slot.
CameraImage render_depth(const BladeSlotGeometry& geometry, const DepthCamera& camera,
                         const RigidTransform& world_T_hand, const RigidTransform& world_T_slot);

/// The eye-in-hand key points: the slot opening's four corners (BladeSlotGeometry's order) in the
/// hand frame, as the 2D task's two corners.
std::array<Eigen::Vector3d, 4> opening_corners_in_hand(const BladeSlotGeometry& geometry,
                                                       const RigidTransform& world_T_hand,
                                                       const RigidTransform& world_T_slot);

}  // namespace handcentric::sim::insert3d
