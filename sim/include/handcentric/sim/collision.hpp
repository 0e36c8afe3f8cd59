#pragma once
// Exact collision between the peg and the hole, through Box2D (2.4.1).
//
// Box2D is float-only and its polygons carry a 0.01 skin (b2_polygonRadius) that b2TestOverlap
// counts: two skins, 0.02, against a per-side gap of 0.05 in this task. So every query is made
// (a) in the hole's own frame, where coordinates stay near the origin and float rounding is
// ~1e-6 cm, and (b) with b2Distance and useRadii = false: the distance between the true
// rectangles, without the skin.
//
// A pose collides when that distance is at most kContactDistance (touching counts).
// A motion between two poses (linear in (theta, x, y) in the hole frame) is checked continuously
// by conservative advancement: v = |dp| + r |dtheta| bounds the speed of every peg point per unit
// of the motion parameter (r = peg_radius()), so at a query with distance d no peg point can
// reach a wall before the parameter advances by d / v. The checker advances by max(d, c/4) / v:
// exact whenever the peg is more than c/4 from every wall, and never coarser than "no peg point
// moves more than c/4 between two queries" near the walls (the issue's bar).
//
// Not thread-safe: queries() counts through a mutable member; use one checker per thread.
#include <cstdint>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/sim/geometry.hpp"

namespace handcentric::sim {

/// Distances at or below this (cm) count as contact: 1 micrometre, ~100x float rounding near the
/// hole.
constexpr double kContactDistance = 1e-4;

/// The pose at parameter s in [0, 1] of the motion from `from` to `to`, linear in (theta, x, y)
/// with the angle difference wrapped into (-pi, pi]. Both poses must be planar.
RigidTransform interpolate_planar(const RigidTransform& from, const RigidTransform& to, double s);

class CollisionChecker {
 public:
  /// Throws InvalidArgument for a bad geometry (see PegHoleGeometry::validate).
  explicit CollisionChecker(const PegHoleGeometry& geometry = PegHoleGeometry());

  const PegHoleGeometry& geometry() const { return geometry_; }

  /// The distance (cm) between the peg and the nearest wall for the hand at hole_T_hand (planar);
  /// 0 when they overlap.
  double distance(const RigidTransform& hole_T_hand) const;

  /// distance(hole_T_hand) <= kContactDistance.
  bool collides(const RigidTransform& hole_T_hand) const;

  /// Whether the peg touches the hole anywhere on the motion from hole_T_hand_from to
  /// hole_T_hand_to (both ends included), checked continuously as described above.
  bool motion_collides(const RigidTransform& hole_T_hand_from,
                       const RigidTransform& hole_T_hand_to) const;

  /// Distance queries made so far by this checker (for benchmarks and tests).
  std::uint64_t queries() const { return queries_; }

 private:
  PegHoleGeometry geometry_;
  mutable std::uint64_t queries_ = 0;
};

}  // namespace handcentric::sim
