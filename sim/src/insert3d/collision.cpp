#include "handcentric/sim/insert3d/collision.hpp"

#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <array>
#include <limits>

#include "handcentric/core/so3.hpp"

namespace handcentric::sim::insert3d {

struct CollisionChecker::Shapes {
  fcl::Boxd blade;
  fcl::Transform3d hand_T_blade_centre;
  std::array<fcl::Boxd, 5> walls;
  std::array<fcl::Transform3d, 5> slot_T_wall_centre;

  explicit Shapes(const BladeSlotGeometry& geometry)
      : blade(geometry.blade_in_hand().size()),
        walls{
            fcl::Boxd(geometry.slot_walls()[0].size()), fcl::Boxd(geometry.slot_walls()[1].size()),
            fcl::Boxd(geometry.slot_walls()[2].size()), fcl::Boxd(geometry.slot_walls()[3].size()),
            fcl::Boxd(geometry.slot_walls()[4].size())} {
    hand_T_blade_centre = fcl::Transform3d::Identity();
    hand_T_blade_centre.translation() = geometry.blade_in_hand().centre();
    const auto boxes = geometry.slot_walls();
    for (std::size_t i = 0; i < boxes.size(); ++i) {
      slot_T_wall_centre[i] = fcl::Transform3d::Identity();
      slot_T_wall_centre[i].translation() = boxes[i].centre();
    }
  }
};

RigidTransform interpolate(const RigidTransform& from, const RigidTransform& to, double s) {
  const Eigen::Vector3d omega = so3::log(from.rotation().inverse_compose(to.rotation()).matrix());
  const Eigen::Vector3d p = from.translation() + s * (to.translation() - from.translation());
  return RigidTransform::unchecked(from.rotation().matrix() * so3::exp(s * omega), p);
}

CollisionChecker::CollisionChecker(const BladeSlotGeometry& geometry) : geometry_(geometry) {
  geometry_.validate();
  shapes_ = std::make_unique<const Shapes>(geometry_);
}

CollisionChecker::~CollisionChecker() = default;
CollisionChecker::CollisionChecker(CollisionChecker&&) noexcept = default;
CollisionChecker& CollisionChecker::operator=(CollisionChecker&&) noexcept = default;

double CollisionChecker::distance(const RigidTransform& slot_T_hand) const {
  ++queries_;
  fcl::Transform3d slot_T_blade = fcl::Transform3d::Identity();
  slot_T_blade.linear() = slot_T_hand.rotation().matrix();
  slot_T_blade.translation() = slot_T_hand.translation();
  slot_T_blade = slot_T_blade * shapes_->hand_T_blade_centre;
  double nearest = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < shapes_->walls.size(); ++i) {
    fcl::CollisionRequestd collision_request;
    fcl::CollisionResultd collision_result;
    fcl::collide(&shapes_->blade, slot_T_blade, &shapes_->walls[i], shapes_->slot_T_wall_centre[i],
                 collision_request, collision_result);
    if (collision_result.isCollision()) return 0.0;
    // FCL's own GJK in double (GST_INDEP), iterated to 1e-12: libccd's default stops at 1e-6.
    fcl::DistanceRequestd distance_request(false, false, 0.0, 0.0, 1e-12, fcl::GST_INDEP);
    fcl::DistanceResultd distance_result;
    const double d =
        fcl::distance(&shapes_->blade, slot_T_blade, &shapes_->walls[i],
                      shapes_->slot_T_wall_centre[i], distance_request, distance_result);
    nearest = std::min(nearest, std::max(d, 0.0));
  }
  return nearest;
}

bool CollisionChecker::collides(const RigidTransform& slot_T_hand) const {
  return distance(slot_T_hand) <= kContactDistance;
}

bool CollisionChecker::motion_collides(const RigidTransform& slot_T_hand_from,
                                       const RigidTransform& slot_T_hand_to) const {
  const Eigen::Vector3d omega =
      so3::log(slot_T_hand_from.rotation().inverse_compose(slot_T_hand_to.rotation()).matrix());
  const double speed = (slot_T_hand_to.translation() - slot_T_hand_from.translation()).norm() +
                       geometry_.blade_radius() * omega.norm();
  double s = 0.0;
  for (;;) {
    const double d = distance(interpolate(slot_T_hand_from, slot_T_hand_to, s));
    if (d <= kContactDistance) return true;
    if (s >= 1.0 || speed == 0.0) return false;
    s = std::min(1.0, s + (d - 0.5 * kContactDistance) / speed);
  }
}

}  // namespace handcentric::sim::insert3d
