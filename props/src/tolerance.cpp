#include "handcentric/props/tolerance.hpp"

#include <algorithm>
#include <Eigen/LU>
#include <cmath>

#include "handcentric/core/format.hpp"
#include "handcentric/core/sampling.hpp"

namespace handcentric::props {

double length_scale(const Scene& scene) {
  double scale = 0.0;
  for (const auto& T : scene.world_T_hand_history) scale = std::max(scale, T.translation().norm());
  for (const auto& T : scene.world_T_hand_chunk) scale = std::max(scale, T.translation().norm());
  for (const auto& x : scene.world_points) scale = std::max(scale, x.norm());
  for (const auto& x : scene.hand_points) scale = std::max(scale, x.norm());
  for (const auto& named : scene.extra_poses)
    scale = std::max(scale, named.second.translation().norm());
  return scale;
}

double pointwise_tolerance(const Scene& scene, const Scene& moved, double relative) {
  return relative * (1.0 + std::max(length_scale(scene), length_scale(moved)));
}

double distance_from_identity(const RigidTransform& g, const Scene& scene) {
  return g.rotation().angle() + g.translation().norm() / (1.0 + length_scale(scene));
}

double rounding_cap(double unit_roundoff, double length_scale) {
  return std::sqrt(unit_roundoff) * (1.0 + length_scale);
}

double off_case_scale(double unit_roundoff) {
  return std::max(1e-9, 1e3 * unit_roundoff);
}

namespace {

double random_sign(std::mt19937_64& rng) {
  return (rng() & 1U) != 0U ? 1.0 : -1.0;
}

Eigen::Vector3d random_direction(std::mt19937_64& rng) {
  Eigen::Vector3d v;
  do {
    v = Eigen::Vector3d(standard_normal(rng), standard_normal(rng), standard_normal(rng));
  } while (!(v.norm() > 1e-12));
  return v.normalized();
}

// A random unit direction, in the plane z = 0 when planar.
Eigen::Vector3d random_direction(std::mt19937_64& rng, bool planar) {
  if (!planar) return random_direction(rng);
  Eigen::Vector3d v;
  do {
    v = Eigen::Vector3d(standard_normal(rng), standard_normal(rng), 0.0);
  } while (!(v.norm() > 1e-12));
  return v.normalized();
}

// A random rotation axis: any, or +-z when planar (the plane's rotations).
Eigen::Vector3d random_axis(std::mt19937_64& rng, bool planar) {
  return planar ? Eigen::Vector3d(0.0, 0.0, random_sign(rng)) : random_direction(rng);
}

// Every pose, point and scalar of `scene` mapped through the given functions.
template <typename Pose, typename Point, typename Scalar>
Scene moved_each(const Scene& scene, Pose&& pose, Point&& point, Scalar&& scalar) {
  Scene out = scene;
  for (RigidTransform& T : out.world_T_hand_history) T = pose(T);
  for (RigidTransform& T : out.world_T_hand_chunk) T = pose(T);
  for (auto& named : out.extra_poses) named.second = pose(named.second);
  for (Eigen::Vector3d& x : out.world_points) x = point(x);
  for (Eigen::Vector3d& x : out.hand_points) x = point(x);
  for (auto& named : out.scalars) named.second = scalar(named.second);
  return out;
}

}  // namespace

Scene rounding_perturbation(const Scene& scene, double unit_roundoff, std::mt19937_64& rng,
                            bool planar) {
  const double step = kRoundingPerturbationUlps * unit_roundoff;
  auto coordinates = [&](Eigen::Vector3d x) {
    for (int i = 0; i < 3; ++i) x(i) *= 1.0 + step * random_sign(rng);
    return x;
  };
  auto pose = [&](const RigidTransform& T) {
    return RigidTransform::unchecked(
        T.rotation().matrix() * Rotation::exp(step * random_axis(rng, planar)).matrix(),
        coordinates(T.translation()));
  };
  return moved_each(scene, pose, coordinates,
                    [&](double x) { return x * (1.0 + step * random_sign(rng)); });
}

Scene nearby_scene(const Scene& scene, double eta, std::mt19937_64& rng, bool planar) {
  const double reach = eta * (1.0 + length_scale(scene));
  auto point = [&](const Eigen::Vector3d& x) -> Eigen::Vector3d {
    return x + reach * random_direction(rng, planar);
  };
  auto pose = [&](const RigidTransform& T) {
    Twist twist;
    twist << reach * random_direction(rng, planar), eta * random_axis(rng, planar);
    return T * RigidTransform::exp(twist);
  };
  return moved_each(scene, pose, point, [&](double x) {
    return x + eta * std::max(1.0, std::abs(x)) * random_sign(rng);
  });
}

double output_pose_tolerance(double unit_roundoff) {
  return std::max(kOutputPoseTolerance, 2.0 * std::sqrt(unit_roundoff));
}

std::string pose_defect(const Eigen::Matrix4d& M, double tolerance) {
  if (!M.allFinite()) return "it holds a non-finite number";
  const double last_row =
      std::max({std::abs(M(3, 0)), std::abs(M(3, 1)), std::abs(M(3, 2)), std::abs(M(3, 3) - 1.0)});
  if (!(last_row <= tolerance)) {
    return "its last row is (" + format_number(M(3, 0)) + ", " + format_number(M(3, 1)) + ", " +
           format_number(M(3, 2)) + ", " + format_number(M(3, 3)) + "), not (0, 0, 0, 1)";
  }
  const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
  const double orthonormality =
      (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff<Eigen::PropagateNaN>();
  const double determinant = R.determinant();
  if (!(orthonormality <= tolerance) || !(std::abs(determinant - 1.0) <= tolerance)) {
    return "its rotation block is not a rotation: |R^T R - I|_max = " +
           format_number(orthonormality) + ", det R = " + format_number(determinant) +
           " (each must be within " + format_number(tolerance) + " of a rotation's 0 and 1)";
  }
  return {};
}

bool near_identity(const RigidTransform& g, const Scene& scene) {
  return distance_from_identity(g, scene) < kNearIdentity;
}

}  // namespace handcentric::props
