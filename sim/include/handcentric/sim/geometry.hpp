#pragma once
// The peg and the hole of the 2D insertion task (Sec. 4.2, Figure 2), in cm.
//
//   Peg  : a rectangle kPegWidth wide and kPegLength long, held rigidly. The hand frame sits at
//          the centre of the peg's top edge; the peg extends along the hand's -y axis, so its tip
//          (bottom edge centre) is hand_T_tip = (0, -kPegLength).
//   Hole : a U of three rectangles (left wall, right wall, bottom), inner width
//          kPegWidth + clearance, depth kHoleDepth. The hole frame sits at the centre of the
//          opening with +y pointing out of the hole, so the inside is y in [-kHoleDepth, 0].
//
// The 2D task lives in SE(3) as the planar subgroup RigidTransform::planar(theta, x, y).
#include <Eigen/Core>
#include <array>

#include "handcentric/core/rigid_transform.hpp"

namespace handcentric::sim {

constexpr double kPegWidth = 2.0;
constexpr double kPegLength = 8.0;
constexpr double kHoleDepth = 6.0;
constexpr double kWallThickness = 2.0;
constexpr double kDefaultClearance = 0.1;  ///< 0.05 per side
/// Success: the peg tip at least this deep below the opening, inside the hole (is_inserted).
constexpr double kSuccessDepth = 5.0;

/// An axis-aligned rectangle [x0, x1] x [y0, y1] in some frame.
struct Box {
  double x0, x1, y0, y1;
};

struct PegHoleGeometry {
  double clearance = kDefaultClearance;

  /// Throws InvalidArgument unless 0 < clearance < kPegWidth (a finite number).
  void validate() const;

  double inner_width() const { return kPegWidth + clearance; }

  /// The peg in the hand frame: x in [-w/2, w/2], y in [-kPegLength, 0].
  Box peg_in_hand() const;

  /// The three wall rectangles in the hole frame: left, right, bottom.
  std::array<Box, 3> hole_walls() const;

  /// The two corners of the hole's opening in the hole frame: (-inner_width/2, 0) then
  /// (+inner_width/2, 0). They are the eye-in-hand key points of Sec. 4.2.
  std::array<Eigen::Vector3d, 2> opening_corners() const;

  /// The four corners of the peg in the hand frame (counter-clockwise from bottom-left).
  std::array<Eigen::Vector3d, 4> peg_corners() const;

  /// The largest distance of a peg point from the hand frame's origin: bounds how far any
  /// peg point moves when the hand turns by an angle (|d point| <= radius * |d theta|).
  double peg_radius() const;
};

/// The peg tip (0, -kPegLength) in the hole frame, for the hand at hole_T_hand.
Eigen::Vector3d tip_in_hole(const RigidTransform& hole_T_hand);

/// Whether the hand at hole_T_hand has the peg tip inside the hole's cavity, at least
/// kSuccessDepth deep: -kHoleDepth <= y <= -kSuccessDepth and |x| < inner_width / 2. The floor
/// matters: a tip behind the hole's bottom wall (y < -kHoleDepth - kWallThickness), reached by
/// going around the hole, lies under the opening too but is not an insertion. Inside the
/// cavity the peg (longer than the hole is deep) passes through the opening.
bool is_inserted(const RigidTransform& hole_T_hand,
                 const PegHoleGeometry& geometry = PegHoleGeometry());

/// The planar coordinates (theta, x, y) of a planar pose (theta from the rotation's first column).
Eigen::Vector3d planar_coordinates(const RigidTransform& pose);

}  // namespace handcentric::sim
