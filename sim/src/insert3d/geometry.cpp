#include "handcentric/sim/insert3d/geometry.hpp"

#include <cmath>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"

namespace handcentric::sim::insert3d {

void BladeSlotGeometry::validate() const {
  if (!std::isfinite(clearance_per_side) || clearance_per_side <= 0.0 ||
      clearance_per_side > kMaxClearancePerSide) {
    throw InvalidArgument("blade-slot clearance per side must be in (0, " +
                          format_number(kMaxClearancePerSide) + "] cm, got " +
                          format_number(clearance_per_side) + "; e.g. 0.1");
  }
}

Box3 BladeSlotGeometry::blade_in_hand() const {
  return Box3{Eigen::Vector3d(-0.5 * kBladeThickness, -0.5 * kBladeWidth, -kBladeLength),
              Eigen::Vector3d(0.5 * kBladeThickness, 0.5 * kBladeWidth, 0.0)};
}

std::array<Box3, 5> BladeSlotGeometry::slot_walls() const {
  const double hx = inner_half_x();
  const double hy = inner_half_y();
  const double t = kSlotWallThickness;
  const double outer_y = hy + t;
  return {
      Box3{Eigen::Vector3d(-hx - t, -outer_y, -kSlotDepth),
           Eigen::Vector3d(-hx, outer_y, 0.0)},  // plate -x
      Box3{Eigen::Vector3d(hx, -outer_y, -kSlotDepth),
           Eigen::Vector3d(hx + t, outer_y, 0.0)},                                       // plate +x
      Box3{Eigen::Vector3d(-hx, -outer_y, -kSlotDepth), Eigen::Vector3d(hx, -hy, 0.0)},  // end -y
      Box3{Eigen::Vector3d(-hx, hy, -kSlotDepth), Eigen::Vector3d(hx, outer_y, 0.0)},    // end +y
      Box3{Eigen::Vector3d(-hx - t, -outer_y, -kSlotDepth - t),
           Eigen::Vector3d(hx + t, outer_y, -kSlotDepth)},  // bottom
  };
}

std::array<Eigen::Vector3d, 4> BladeSlotGeometry::opening_corners() const {
  const double hx = inner_half_x();
  const double hy = inner_half_y();
  return {Eigen::Vector3d(-hx, -hy, 0.0), Eigen::Vector3d(hx, -hy, 0.0),
          Eigen::Vector3d(hx, hy, 0.0), Eigen::Vector3d(-hx, hy, 0.0)};
}

std::array<Eigen::Vector3d, 8> BladeSlotGeometry::blade_corners() const {
  const Box3 blade = blade_in_hand();
  std::array<Eigen::Vector3d, 8> corners;
  for (int i = 0; i < 8; ++i) {
    corners[static_cast<std::size_t>(i)] = Eigen::Vector3d((i & 1) ? blade.max.x() : blade.min.x(),
                                                           (i & 2) ? blade.max.y() : blade.min.y(),
                                                           (i & 4) ? blade.max.z() : blade.min.z());
  }
  return corners;
}

double BladeSlotGeometry::blade_radius() const {
  const Box3 blade = blade_in_hand();
  return std::hypot(0.5 * kBladeThickness, 0.5 * kBladeWidth, blade.min.z());
}

Eigen::Vector3d tip_in_slot(const RigidTransform& slot_T_hand) {
  return slot_T_hand * Eigen::Vector3d(0.0, 0.0, -kBladeLength);
}

bool inserted(const BladeSlotGeometry& geometry, const RigidTransform& slot_T_hand) {
  const Eigen::Vector3d tip = tip_in_slot(slot_T_hand);
  return tip.z() <= -kSuccessDepth && tip.z() >= -kSlotDepth &&
         std::abs(tip.x()) < geometry.inner_half_x() && std::abs(tip.y()) < geometry.inner_half_y();
}

}  // namespace handcentric::sim::insert3d
