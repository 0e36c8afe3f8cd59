#pragma once
// Solid: a shape a camera can see (a box, a sphere, or the half-space below a plane), placed in
// some frame F by F_T_solid, with a colour for shaded images. Ray hits are computed in the
// solid's own frame, so a solid and a camera that move together by any g give the same hit
// whatever g is (up to rounding in forming solid_T_camera): what makes an eye-in-hand image
// invariant (Sec. 3.2 of "Guaranteed SE(3)-Equivariant Control via Hand-Centric Behavior
// Cloning").
#include <Eigen/Core>
#include <optional>

#include "handcentric/core/rigid_transform.hpp"

namespace handcentric {

struct Solid {
  enum class Shape {
    box,     ///< |x_i| <= half_extents_i in the solid's frame
    sphere,  ///< |x| <= radius (half_extents.x()) about the solid's origin
    plane,   ///< the half-space z <= 0 of the solid's frame (a floor seen from above)
  };

  Shape shape = Shape::sphere;
  RigidTransform frame_T_solid;
  Eigen::Vector3d half_extents = Eigen::Vector3d::Constant(1.0);
  /// Red, green, blue reflectance in [0, 1].
  Eigen::Vector3d albedo = Eigen::Vector3d::Constant(0.8);

  /// Throw InvalidArgument naming the value and the fix: non-positive or non-finite sizes, an
  /// albedo outside [0, 1].
  static Solid box(const RigidTransform& frame_T_box, const Eigen::Vector3d& half_extents,
                   const Eigen::Vector3d& albedo = Eigen::Vector3d::Constant(0.8));
  static Solid sphere(const Eigen::Vector3d& frame_centre, double radius,
                      const Eigen::Vector3d& albedo = Eigen::Vector3d::Constant(0.8));
  static Solid plane(const RigidTransform& frame_T_plane,
                     const Eigen::Vector3d& albedo = Eigen::Vector3d::Constant(0.8));
};

/// Where a ray first meets a solid: origin + t direction, and the outward unit normal there, both
/// in the frame the ray was given in.
struct RayHit {
  double t = 0.0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

/// The first hit with t >= 0 of the ray solid_origin + t solid_direction, both in the solid's
/// frame, or nothing. A ray that starts inside the solid hits at t = 0 with the normal facing
/// back along the ray. The direction need not be unit: t is in its units.
std::optional<RayHit> hit_in_solid_frame(const Solid& solid, const Eigen::Vector3d& solid_origin,
                                         const Eigen::Vector3d& solid_direction);

}  // namespace handcentric
