#include "handcentric/core/solid.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"

namespace handcentric {
namespace {

void check_albedo(const Eigen::Vector3d& albedo) {
  if (!albedo.allFinite() || albedo.minCoeff() < 0.0 || albedo.maxCoeff() > 1.0) {
    throw InvalidArgument("a solid's albedo must be three numbers in [0, 1], got " +
                          format_matrix(albedo) + "; e.g. 0.8 0.8 0.8");
  }
}

// The normal that faces back along the ray, for a ray that starts inside a solid.
Eigen::Vector3d facing_back(const Eigen::Vector3d& direction) {
  const double length = direction.norm();
  return length > 0.0 ? Eigen::Vector3d(-direction / length) : Eigen::Vector3d::UnitZ();
}

std::optional<RayHit> hit_box(const Eigen::Vector3d& half, const Eigen::Vector3d& origin,
                              const Eigen::Vector3d& direction) {
  // The slab method: the ray is inside the box between the largest entry and the smallest exit.
  double t_near = 0.0;
  double t_far = std::numeric_limits<double>::infinity();
  int entry_axis = -1;
  for (int axis = 0; axis < 3; ++axis) {
    if (direction(axis) == 0.0) {
      if (origin(axis) < -half(axis) || origin(axis) > half(axis)) return std::nullopt;
      continue;
    }
    double t0 = (-half(axis) - origin(axis)) / direction(axis);
    double t1 = (half(axis) - origin(axis)) / direction(axis);
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > t_near) {
      t_near = t0;
      entry_axis = axis;
    }
    t_far = std::min(t_far, t1);
    if (t_near > t_far) return std::nullopt;
  }
  if (entry_axis < 0) return RayHit{0.0, facing_back(direction)};
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  normal(entry_axis) = direction(entry_axis) > 0.0 ? -1.0 : 1.0;
  return RayHit{t_near, normal};
}

std::optional<RayHit> hit_sphere(double radius, const Eigen::Vector3d& origin,
                                 const Eigen::Vector3d& direction) {
  // |origin + t direction|^2 = radius^2, the nearer root with t >= 0.
  const double a = direction.squaredNorm();
  const double c = origin.squaredNorm() - radius * radius;
  if (c <= 0.0) return RayHit{0.0, facing_back(direction)};
  const double b = origin.dot(direction);
  if (a == 0.0 || b >= 0.0) return std::nullopt;  // pointing away from an outside sphere
  const double discriminant = b * b - a * c;
  if (discriminant < 0.0) return std::nullopt;
  // c / q rather than q / a: the root without cancellation (Numerical Recipes' quadratic).
  const double q = -b + std::sqrt(discriminant);
  const double t = c / q;
  return RayHit{t, (origin + t * direction) / radius};
}

std::optional<RayHit> hit_plane(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) {
  if (origin.z() <= 0.0) return RayHit{0.0, facing_back(direction)};
  if (direction.z() >= 0.0) return std::nullopt;
  return RayHit{-origin.z() / direction.z(), Eigen::Vector3d::UnitZ()};
}

}  // namespace

Solid Solid::box(const RigidTransform& frame_T_box, const Eigen::Vector3d& half_extents,
                 const Eigen::Vector3d& albedo) {
  if (!half_extents.allFinite() || half_extents.minCoeff() <= 0.0) {
    throw InvalidArgument("a box's half extents must be positive and finite, got " +
                          format_matrix(half_extents) + "; e.g. 0.05 0.05 0.05");
  }
  check_albedo(albedo);
  return Solid{Shape::box, frame_T_box, half_extents, albedo};
}

Solid Solid::sphere(const Eigen::Vector3d& frame_centre, double radius,
                    const Eigen::Vector3d& albedo) {
  if (!std::isfinite(radius) || radius <= 0.0) {
    throw InvalidArgument("a sphere's radius must be positive and finite, got " +
                          format_number(radius) + "; e.g. 0.02");
  }
  if (!frame_centre.allFinite()) {
    throw InvalidArgument("a sphere's centre must be finite, got " + format_matrix(frame_centre));
  }
  check_albedo(albedo);
  return Solid{Shape::sphere, RigidTransform::from_translation(frame_centre),
               Eigen::Vector3d::Constant(radius), albedo};
}

Solid Solid::plane(const RigidTransform& frame_T_plane, const Eigen::Vector3d& albedo) {
  check_albedo(albedo);
  return Solid{Shape::plane, frame_T_plane, Eigen::Vector3d::Constant(1.0), albedo};
}

std::optional<RayHit> hit_in_solid_frame(const Solid& solid, const Eigen::Vector3d& solid_origin,
                                         const Eigen::Vector3d& solid_direction) {
  switch (solid.shape) {
    case Solid::Shape::box:
      return hit_box(solid.half_extents, solid_origin, solid_direction);
    case Solid::Shape::sphere:
      return hit_sphere(solid.half_extents.x(), solid_origin, solid_direction);
    case Solid::Shape::plane:
      return hit_plane(solid_origin, solid_direction);
  }
  return std::nullopt;
}

}  // namespace handcentric
