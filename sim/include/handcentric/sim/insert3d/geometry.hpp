#pragma once
// The blade and the slot of the 3D insertion task, in cm: the simulated analogue of the blade
// insertion of "Guaranteed SE(3)-Equivariant Control via Hand-Centric Behavior Cloning"
// (Table 2), placed anywhere in SE(3).
//
//   Blade: a box kBladeThickness (x) by kBladeWidth (y) by kBladeLength (z), held rigidly. The
//          hand frame sits at the centre of the blade's top face; the blade extends along the
//          hand's -z axis, so its tip (the centre of the bottom face) is hand_T_tip = (0, 0, -8).
//   Slot : a gap in a block, as wide as the blade plus `clearance` on each side in x and in y,
//          kSlotDepth deep. The slot frame sits at the centre of the opening with +z pointing
//          out of the slot, so the inside is |x| <= t/2 + c, |y| <= w/2 + c, z in [-depth, 0].
//          The block is five axis-aligned boxes in the slot frame: two side plates (x), two end
//          walls (y) and the bottom, each kSlotWallThickness thick, their tops at z = 0.
//
// Success: the blade tip inside the slot, at least kSuccessDepth below the opening (and not
// below the slot's floor), with no contact at any step.
#include <Eigen/Core>

#include <array>

#include "handcentric/core/rigid_transform.hpp"

namespace handcentric::sim::insert3d {

constexpr double kBladeThickness = 0.4;
constexpr double kBladeWidth = 4.0;
constexpr double kBladeLength = 8.0;
constexpr double kSlotDepth = 6.0;
constexpr double kSlotWallThickness = 2.0;
/// Gap between the centred blade and the slot on each side, in x and in y.
constexpr double kDefaultClearancePerSide = 0.1;
/// The largest clearance accepted: beyond it the slot is no longer a tight fit.
constexpr double kMaxClearancePerSide = 1.0;
/// Success: the blade tip at least this deep below the opening.
constexpr double kSuccessDepth = 5.0;

/// An axis-aligned box [min, max] in some frame.
struct Box3 {
  Eigen::Vector3d min;
  Eigen::Vector3d max;

  Eigen::Vector3d centre() const { return 0.5 * (min + max); }
  Eigen::Vector3d size() const { return max - min; }
};

struct BladeSlotGeometry {
  double clearance_per_side = kDefaultClearancePerSide;

  /// Throws InvalidArgument unless 0 < clearance_per_side <= kMaxClearancePerSide (finite).
  void validate() const;

  /// Half the slot's inner size in x and y: t/2 + c and w/2 + c.
  double inner_half_x() const { return 0.5 * kBladeThickness + clearance_per_side; }
  double inner_half_y() const { return 0.5 * kBladeWidth + clearance_per_side; }

  /// The blade in the hand frame: |x| <= t/2, |y| <= w/2, z in [-kBladeLength, 0].
  Box3 blade_in_hand() const;

  /// The block's five boxes in the slot frame: plates at -x and +x, end walls at -y and +y,
  /// bottom.
  std::array<Box3, 5> slot_walls() const;

  /// The four corners of the slot's opening (z = 0) in the slot frame, counter-clockwise from
  /// (-x, -y): the eye-in-hand key points.
  std::array<Eigen::Vector3d, 4> opening_corners() const;

  /// The eight corners of the blade in the hand frame.
  std::array<Eigen::Vector3d, 8> blade_corners() const;

  /// The largest distance of a blade point from the hand frame's origin: no blade point moves
  /// more than radius * angle when the hand turns by an angle about an axis through its origin.
  double blade_radius() const;
};

/// The blade tip (0, 0, -kBladeLength) in the slot frame, for the hand at slot_T_hand.
Eigen::Vector3d tip_in_slot(const RigidTransform& slot_T_hand);

/// Whether the hand at slot_T_hand has the blade tip inside the slot, at least kSuccessDepth
/// deep: -kSlotDepth <= z <= -kSuccessDepth and inside the footprint (contact is checked
/// separately). The floor matters: a tip under the block (z < -kSlotDepth -
/// kSlotWallThickness), reached by going around it, lies inside the footprint too but is not an
/// insertion.
bool inserted(const BladeSlotGeometry& geometry, const RigidTransform& slot_T_hand);

}  // namespace handcentric::sim::insert3d
