// Exact peg-hole collision with b2Distance (useRadii = false) in the hole frame; see collision.hpp.
#include "handcentric/sim/collision.hpp"

#include <box2d/b2_distance.h>  // b2Distance: not included by box2d/box2d.h
#include <box2d/b2_polygon_shape.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace handcentric::sim {
namespace {

b2PolygonShape box_shape(const Box& box) {
  b2PolygonShape shape;
  shape.SetAsBox(static_cast<float>(0.5 * (box.x1 - box.x0)),
                 static_cast<float>(0.5 * (box.y1 - box.y0)),
                 b2Vec2(static_cast<float>(0.5 * (box.x0 + box.x1)),
                        static_cast<float>(0.5 * (box.y0 + box.y1))),
                 0.0f);
  return shape;
}

double wrap_angle(double angle) {
  const double pi = std::numbers::pi;
  angle = std::remainder(angle, 2.0 * pi);  // in [-pi, pi]
  return angle <= -pi ? angle + 2.0 * pi : angle;
}

}  // namespace

RigidTransform interpolate_planar(const RigidTransform& from, const RigidTransform& to, double s) {
  const Eigen::Vector3d a = planar_coordinates(from);
  const Eigen::Vector3d b = planar_coordinates(to);
  const double dtheta = wrap_angle(b(0) - a(0));
  return RigidTransform::planar(a(0) + s * dtheta, a(1) + s * (b(1) - a(1)),
                                a(2) + s * (b(2) - a(2)));
}

CollisionChecker::CollisionChecker(const PegHoleGeometry& geometry) : geometry_(geometry) {
  geometry_.validate();
}

double CollisionChecker::distance(const RigidTransform& hole_T_hand) const {
  const b2PolygonShape peg = box_shape(geometry_.peg_in_hand());
  const Eigen::Vector3d q = planar_coordinates(hole_T_hand);
  b2DistanceInput input;
  input.proxyA.Set(&peg, 0);
  input.transformA = b2Transform(b2Vec2(static_cast<float>(q(1)), static_cast<float>(q(2))),
                                 b2Rot(static_cast<float>(q(0))));
  input.transformB.SetIdentity();  // the hole frame
  input.useRadii = false;          // the true rectangles, without the b2_polygonRadius skin
  double nearest = INFINITY;
  for (const Box& wall : geometry_.hole_walls()) {
    const b2PolygonShape shape = box_shape(wall);
    input.proxyB.Set(&shape, 0);
    b2SimplexCache cache;
    cache.count = 0;
    b2DistanceOutput output;
    b2Distance(&output, &cache, &input);
    ++queries_;
    nearest = std::min(nearest, static_cast<double>(output.distance));
  }
  return nearest;
}

bool CollisionChecker::collides(const RigidTransform& hole_T_hand) const {
  return distance(hole_T_hand) <= kContactDistance;
}

bool CollisionChecker::motion_collides(const RigidTransform& hole_T_hand_from,
                                       const RigidTransform& hole_T_hand_to) const {
  const Eigen::Vector3d a = planar_coordinates(hole_T_hand_from);
  const Eigen::Vector3d b = planar_coordinates(hole_T_hand_to);
  // v bounds the speed (per unit of s) of every peg point along the motion
  const double speed = std::hypot(b(1) - a(1), b(2) - a(2)) +
                       geometry_.peg_radius() * std::abs(wrap_angle(b(0) - a(0)));
  const double finest =
      0.25 * geometry_.clearance;  // never move a peg point more than c/4 unchecked
  double s = 0.0;
  while (true) {
    const RigidTransform pose = s == 0.0 ? hole_T_hand_from
                                : s >= 1.0
                                    ? hole_T_hand_to
                                    : interpolate_planar(hole_T_hand_from, hole_T_hand_to, s);
    const double d = distance(pose);
    if (d <= kContactDistance) return true;
    if (s >= 1.0 || speed == 0.0) return false;
    s = std::min(1.0, s + std::max(d, finest) / speed);
  }
}

}  // namespace handcentric::sim
