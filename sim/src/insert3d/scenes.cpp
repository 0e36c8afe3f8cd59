#include "handcentric/sim/insert3d/scenes.hpp"

#include <cmath>
#include <numbers>
#include <random>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/sim/scenes.hpp"
#include "../scene_helpers.hpp"

namespace handcentric::sim::insert3d {
using detail::radians;
using detail::uniform;

namespace {

/// A rotation by an angle uniform in [0, max_deg] about a uniformly random horizontal axis.
Rotation random_tilt(std::mt19937_64& rng, double max_deg) {
  const double axis_angle = uniform(rng, 0.0, 2.0 * std::numbers::pi);
  const double angle = radians(uniform(rng, 0.0, max_deg));
  return Rotation::exp(angle * Eigen::Vector3d(std::cos(axis_angle), std::sin(axis_angle), 0.0));
}

}  // namespace

TaskScene operator*(const RigidTransform& g, const TaskScene& scene) {
  return TaskScene{g * scene.world_T_slot, g * scene.world_T_hand_start};
}

Rotation rotation_from_xyz_deg(const Eigen::Vector3d& xyz_deg) {
  return Rotation::exp(radians(xyz_deg.x()) * Eigen::Vector3d::UnitX()) *
         Rotation::exp(radians(xyz_deg.y()) * Eigen::Vector3d::UnitY()) *
         Rotation::exp(radians(xyz_deg.z()) * Eigen::Vector3d::UnitZ());
}

SceneDistribution SceneDistribution::rotate(const Eigen::Vector3d& xyz_deg) {
  if (!xyz_deg.allFinite()) {
    throw InvalidArgument("rotation angles must be finite, got " + format_matrix(xyz_deg) +
                          "; give XYZ Euler angles in degrees, e.g. --rotate-deg 90,0,45");
  }
  return {Kind::rotate, xyz_deg};
}

SceneDistribution SceneDistribution::parse(const std::string& name) {
  if (name == "train") return train();
  if (name == "ood") return ood();
  if (name == "random-se3") return random_se3();
  throw InvalidArgument("unknown 3D scene distribution '" + name +
                        "'; use train, ood or random-se3 (or --rotate-deg RX,RY,RZ)");
}

SceneDistribution SceneDistribution::parse_rotate_deg(const std::string& text) {
  Eigen::Vector3d values;
  if (!detail::parse_finite_triple(text, values)) {
    throw InvalidArgument(
        "bad rotation '" + text +
        "'; expected RX,RY,RZ (three finite XYZ Euler angles in degrees), e.g. 90,0,45");
  }
  return rotate(values);
}

std::string SceneDistribution::name() const {
  switch (kind) {
    case Kind::train:
      return "train";
    case Kind::ood:
      return "ood";
    case Kind::random_se3:
      return "random-se3";
    case Kind::rotate:
      return "rotate " + format_number(rotate_deg.x()) + "," + format_number(rotate_deg.y()) + "," +
             format_number(rotate_deg.z());
  }
  return "?";
}

TaskScene sample_scene(const SceneDistribution& distribution, std::uint64_t seed,
                       std::uint64_t index) {
  std::mt19937_64 rng(stream_seed(seed, index));
  // the start relative to the slot first, so it does not depend on the distribution
  const double x = uniform(rng, -kStartMaxAbsXY, kStartMaxAbsXY);
  const double y = uniform(rng, -kStartMaxAbsXY, kStartMaxAbsXY);
  const double z = uniform(rng, kStartMinZ, kStartMaxZ);
  const Rotation yaw =
      Rotation::about_z(radians(uniform(rng, -kStartMaxAbsYawDeg, kStartMaxAbsYawDeg)));
  const Rotation slot_R_hand = random_tilt(rng, kStartMaxTiltDeg) * yaw;
  const RigidTransform slot_T_hand_start(slot_R_hand, Eigen::Vector3d(x, y, z));
  // the slot as in train, then turned on its side for ood
  const Rotation slot_yaw = Rotation::about_z(uniform(rng, 0.0, 2.0 * std::numbers::pi));
  Rotation world_R_slot = random_tilt(rng, kSlotMaxTiltDeg) * slot_yaw;
  const Eigen::Vector3d world_p_slot(uniform(rng, -kWorkspaceHalfWidth, kWorkspaceHalfWidth),
                                     uniform(rng, -kWorkspaceHalfWidth, kWorkspaceHalfWidth),
                                     uniform(rng, 0.0, kWorkspaceMaxHeight));
  const double side_yaw = uniform(rng, 0.0, 2.0 * std::numbers::pi);
  if (distribution.kind == SceneDistribution::Kind::ood) {
    world_R_slot = Rotation::about_z(side_yaw) *
                   Rotation::exp(0.5 * std::numbers::pi * Eigen::Vector3d::UnitY()) * world_R_slot;
  }
  const RigidTransform world_T_slot(world_R_slot, world_p_slot);
  const TaskScene scene{world_T_slot, world_T_slot * slot_T_hand_start};
  switch (distribution.kind) {
    case SceneDistribution::Kind::train:
    case SceneDistribution::Kind::ood:
      return scene;
    case SceneDistribution::Kind::random_se3:
      return random_transform(rng, kRandomTranslationHalfWidth) * scene;
    case SceneDistribution::Kind::rotate:
      return RigidTransform(rotation_from_xyz_deg(distribution.rotate_deg),
                            Eigen::Vector3d::Zero()) *
             scene;
  }
  return scene;
}

std::vector<TaskScene> sample_scenes(const SceneDistribution& distribution, int n,
                                     std::uint64_t seed) {
  return detail::sample_n(sample_scene, distribution, n, seed);
}

}  // namespace handcentric::sim::insert3d
