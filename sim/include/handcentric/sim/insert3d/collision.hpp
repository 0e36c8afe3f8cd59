#pragma once
// Exact collision and distance between the blade and the slot's block, through FCL (kept out of
// this header: a private dependency of handcentric::sim).
//
// Every query is made in the slot's own frame, so coordinates stay within ~20 cm of the origin
// whatever the scene's placement in SE(3): the answer does not depend on the global transform
// beyond double rounding. A pose's distance is the smallest FCL distance between the blade box
// and the block's five boxes (0 when fcl::collide finds an overlap; box-box overlap is exact
// separating-axis arithmetic in FCL). A pose collides when that distance is at most
// kContactDistance: touching counts.
//
// A motion between two poses is the screw-free interpolation of interpolate(): the hand origin
// moves on the straight line, the orientation turns about one fixed axis (in the moving hand's
// frame) at a constant rate. With dp the translation and omega the rotation vector of the whole
// motion, every blade point moves at most v = |dp| + r |omega| per unit of the motion parameter
// (r = blade_radius()). Conservative advancement: at a query with distance d > kContactDistance
// no blade point can reach a wall before the parameter advances by d / v, so the checker
// advances by (d - kContactDistance / 2) / v. The margin absorbs FCL's GJK distance error (below
// 1e-9 cm here, tests/sim); each step moves every point by at most the distance measured, so no
// motion can pass through a wall, or dip into one by any depth above the contact distance,
// between two queries: there is no tunnelling at the clearance, however long the command. Both
// ends are checked. The price is one query per kContactDistance / 2 of travel while grazing a
// wall closer than that; a grazing motion is a contact one query later anyway.
//
// Not thread-safe: queries() counts through a mutable member; use one checker per thread.
#include <cstdint>
#include <memory>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/sim/insert3d/geometry.hpp"

namespace handcentric::sim::insert3d {

/// Distances at or below this (cm) count as contact: 1 micrometre.
constexpr double kContactDistance = 1e-4;

/// The pose at parameter s in [0, 1] of the motion from `from` to `to`: translation linear,
/// rotation from * exp(s log(from^-1 to)) (the short way round). Commutes with any global
/// transform g: interpolate(g from, g to, s) = g interpolate(from, to, s).
RigidTransform interpolate(const RigidTransform& from, const RigidTransform& to, double s);

class CollisionChecker {
 public:
  /// Throws InvalidArgument for a bad geometry (see BladeSlotGeometry::validate).
  explicit CollisionChecker(const BladeSlotGeometry& geometry = BladeSlotGeometry());
  ~CollisionChecker();
  CollisionChecker(CollisionChecker&&) noexcept;
  CollisionChecker& operator=(CollisionChecker&&) noexcept;

  const BladeSlotGeometry& geometry() const { return geometry_; }

  /// The distance (cm) between the blade and the block for the hand at slot_T_hand; 0 when they
  /// overlap.
  double distance(const RigidTransform& slot_T_hand) const;

  /// distance(slot_T_hand) <= kContactDistance.
  bool collides(const RigidTransform& slot_T_hand) const;

  /// Whether the blade touches the block anywhere on the motion from slot_T_hand_from to
  /// slot_T_hand_to (both ends included), by conservative advancement as described above.
  bool motion_collides(const RigidTransform& slot_T_hand_from,
                       const RigidTransform& slot_T_hand_to) const;

  /// Pose queries made so far by this checker (each is one query per block box).
  std::uint64_t queries() const { return queries_; }

 private:
  struct Shapes;  // the FCL boxes
  BladeSlotGeometry geometry_;
  std::unique_ptr<const Shapes> shapes_;
  mutable std::uint64_t queries_ = 0;
};

}  // namespace handcentric::sim::insert3d
