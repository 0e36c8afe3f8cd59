#pragma once
// Scene distributions of the 3D blade insertion: the slot placed in SE(3) the way the paper's
// Table 2 placed it in the lab ("train": opening up; "ood": on its side, the horizontal stacks),
// and placements no lab could try (every orientation, Haar-uniformly).
//
// A task scene is the slot pose and the hand's start pose. The start is drawn RELATIVE to the
// slot first, from the same ranges in every distribution: the hand origin at x, y in [-4, 4],
// z in [12, 20] cm in the slot frame (the tip 4 to 12 cm above the opening when upright), the
// blade turned by a yaw in [-40, 40] deg about the slot's axis and then tilted by at most 25 deg
// about a uniformly random horizontal axis. Then the slot:
//   train      : opening up, tilted by at most 15 deg (about a random horizontal axis, the
//                angle uniform), any yaw; its opening at x, y in [-50, 50], z in [0, 20];
//   ood        : the train slot turned on its side: world_R_slot = Rz(psi) Ry(90 deg) R_train
//                for a yaw psi uniform in [0, 360) deg (the opening faces sideways, +-15 deg);
//   random-se3 : the train scene under a global g with a Haar-uniform rotation and a
//                translation uniform in [-50, 50]^3, drawn after the train scene;
//   rotate     : the train scene under one fixed global rotation about the world origin, from
//                XYZ Euler angles in degrees (--rotate-deg RX,RY,RZ): R = Rx(RX) Ry(RY) Rz(RZ).
// Scene i is drawn from its own stream (seed, i): the same seed gives bit-identical scenes, and
// every non-train scene i is exactly a global transform of train scene i (tests/sim checks it).
#include <cstdint>
#include <string>
#include <vector>

#include "handcentric/core/rigid_transform.hpp"

namespace handcentric::sim::insert3d {

struct TaskScene {
  RigidTransform world_T_slot;
  RigidTransform world_T_hand_start;
};

/// g * scene: both poses move (the whole scene is transformed rigidly).
TaskScene operator*(const RigidTransform& g, const TaskScene& scene);

constexpr double kStartMaxAbsXY = 4.0;
constexpr double kStartMinZ = 12.0;
constexpr double kStartMaxZ = 20.0;
constexpr double kStartMaxAbsYawDeg = 40.0;
constexpr double kStartMaxTiltDeg = 25.0;
constexpr double kSlotMaxTiltDeg = 15.0;
constexpr double kWorkspaceHalfWidth = 50.0;
constexpr double kWorkspaceMaxHeight = 20.0;
/// Half-width of the random-se3 translation cube.
constexpr double kRandomTranslationHalfWidth = 50.0;

struct SceneDistribution {
  enum class Kind { train, ood, random_se3, rotate };
  Kind kind = Kind::train;
  /// For `rotate`: the XYZ Euler angles in degrees.
  Eigen::Vector3d rotate_deg = Eigen::Vector3d::Zero();

  static SceneDistribution train() { return {Kind::train, Eigen::Vector3d::Zero()}; }
  static SceneDistribution ood() { return {Kind::ood, Eigen::Vector3d::Zero()}; }
  static SceneDistribution random_se3() { return {Kind::random_se3, Eigen::Vector3d::Zero()}; }
  /// Throws InvalidArgument for a non-finite angle.
  static SceneDistribution rotate(const Eigen::Vector3d& xyz_deg);
  /// "train", "ood" or "random-se3". Throws InvalidArgument naming the text and the names.
  static SceneDistribution parse(const std::string& name);
  /// "RX,RY,RZ" in degrees (--rotate-deg). Throws InvalidArgument naming the text and the form.
  static SceneDistribution parse_rotate_deg(const std::string& text);

  /// "train", "ood", "random-se3" or "rotate RX,RY,RZ".
  std::string name() const;
};

/// R = Rx(x) Ry(y) Rz(z), angles in degrees.
Rotation rotation_from_xyz_deg(const Eigen::Vector3d& xyz_deg);

/// Scene `index` of the stream `seed`.
TaskScene sample_scene(const SceneDistribution& distribution, std::uint64_t seed,
                       std::uint64_t index);

/// Scenes 0..n-1 of the stream `seed`. Throws InvalidArgument for n < 0.
std::vector<TaskScene> sample_scenes(const SceneDistribution& distribution, int n,
                                     std::uint64_t seed);

}  // namespace handcentric::sim::insert3d
