#include "handcentric/sim/geometry.hpp"

#include <cmath>
#include <string>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"

namespace handcentric::sim {

void PegHoleGeometry::validate() const {
  if (!std::isfinite(clearance) || clearance <= 0.0 || clearance >= kPegWidth) {
    throw InvalidArgument("clearance must be in (0, " + format_number(kPegWidth) + ") cm, got " +
                          format_number(clearance) + "; the paper's task uses 0.1");
  }
}

Box PegHoleGeometry::peg_in_hand() const {
  return Box{-0.5 * kPegWidth, 0.5 * kPegWidth, -kPegLength, 0.0};
}

std::array<Box, 3> PegHoleGeometry::hole_walls() const {
  const double half = 0.5 * inner_width();
  const double outer = half + kWallThickness;
  return {Box{-outer, -half, -kHoleDepth, 0.0},                            // left wall
          Box{half, outer, -kHoleDepth, 0.0},                              // right wall
          Box{-outer, outer, -kHoleDepth - kWallThickness, -kHoleDepth}};  // bottom
}

std::array<Eigen::Vector3d, 2> PegHoleGeometry::opening_corners() const {
  const double half = 0.5 * inner_width();
  return {Eigen::Vector3d(-half, 0.0, 0.0), Eigen::Vector3d(half, 0.0, 0.0)};
}

std::array<Eigen::Vector3d, 4> PegHoleGeometry::peg_corners() const {
  const Box peg = peg_in_hand();
  return {Eigen::Vector3d(peg.x0, peg.y0, 0.0), Eigen::Vector3d(peg.x1, peg.y0, 0.0),
          Eigen::Vector3d(peg.x1, peg.y1, 0.0), Eigen::Vector3d(peg.x0, peg.y1, 0.0)};
}

double PegHoleGeometry::peg_radius() const {
  return std::hypot(0.5 * kPegWidth, kPegLength);
}

Eigen::Vector3d tip_in_hole(const RigidTransform& hole_T_hand) {
  return hole_T_hand * Eigen::Vector3d(0.0, -kPegLength, 0.0);
}

bool is_inserted(const RigidTransform& hole_T_hand, const PegHoleGeometry& geometry) {
  const Eigen::Vector3d tip = tip_in_hole(hole_T_hand);
  return tip.y() <= -kSuccessDepth && tip.y() >= -kHoleDepth &&
         std::abs(tip.x()) < 0.5 * geometry.inner_width();
}

Eigen::Vector3d planar_coordinates(const RigidTransform& pose) {
  const Eigen::Matrix3d& R = pose.rotation().matrix();
  return Eigen::Vector3d(std::atan2(R(1, 0), R(0, 0)), pose.translation().x(),
                         pose.translation().y());
}

}  // namespace handcentric::sim
