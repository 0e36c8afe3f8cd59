#pragma once
// Scene distributions of the 2D insertion task (Sec. 4.2, "Generalization").
//
// A task scene is the hole pose and the hand's start pose. The start is drawn RELATIVE to the
// hole: hole_T_hand_start = planar(a, x, y) with x in [-6, 6], y in [12, 20] (cm), a in
// [-40, 40] deg. The hole's opening is placed uniformly in the workspace [-50, 50]^2 and turned
// by a hole angle (the angle of the hole's +y from world +y):
//   train : opening up (0 +- 10 deg) for half the scenes, sideways (+90 +- 10 or -90 +- 10,
//           a quarter each) for the other half;
//   ood   : bottom-up (180 +- 10 deg);
//   A:B   : uniform in [A, B] deg (--hole-angle-deg A:B).
// Scene i is drawn from its own stream (seed, i), relative start first: the same seed gives the
// same relative starts in every distribution, so each OOD scene is exactly a global planar
// transform of the train scene with the same index (tests/sim checks it).
#include <cstdint>
#include <string>
#include <vector>

#include "handcentric/core/rigid_transform.hpp"

namespace handcentric::sim {

struct TaskScene {
  RigidTransform world_T_hole;
  RigidTransform world_T_hand_start;
};

/// g * scene: both poses move (the whole scene is transformed rigidly).
TaskScene operator*(const RigidTransform& g, const TaskScene& scene);

/// Workspace half-width (cm) of the hole's opening position (the default; a distribution may
/// narrow it, sim/difficulty.hpp), and the start-pose ranges.
constexpr double kWorkspaceHalfWidth = 50.0;
constexpr double kStartMaxAbsX = 6.0;
constexpr double kStartMinY = 12.0;
constexpr double kStartMaxY = 20.0;
constexpr double kStartMaxAbsAngleDeg = 40.0;

struct AngleRange {
  double min_deg = 0.0;
  double max_deg = 0.0;
};

struct SceneDistribution {
  std::string name;
  /// Hole-angle ranges; a scene picks one uniformly at random, then an angle uniformly in it.
  /// "train" lists up, up, +90, -90 so that up gets half the scenes.
  std::vector<AngleRange> hole_angles;
  /// The opening's position is uniform in [-w, w]^2 for this w (cm).
  double workspace_half_width = kWorkspaceHalfWidth;

  static SceneDistribution train();
  static SceneDistribution ood();
  /// Uniform in [min_deg, max_deg]. Throws InvalidArgument for non-finite or min > max.
  static SceneDistribution hole_angle_range(double min_deg, double max_deg);
  /// "train", "ood" or "A:B" (degrees). Throws InvalidArgument naming the text and the forms.
  static SceneDistribution parse(const std::string& text);
};

/// Scene `index` of the stream `seed`.
TaskScene sample_scene(const SceneDistribution& distribution, std::uint64_t seed,
                       std::uint64_t index);

/// Scenes 0..n-1 of the stream `seed`. Throws InvalidArgument for n < 0.
std::vector<TaskScene> sample_scenes(const SceneDistribution& distribution, int n,
                                     std::uint64_t seed);

/// A global planar transform from "DEG,X,Y" (rotation about z in degrees, then translation in
/// cm), as the command line takes it. Throws InvalidArgument naming the text and the form.
RigidTransform parse_planar_transform(const std::string& text);

/// g * scene for every scene: "arbitrary global SE(2) transforms of a scene set".
std::vector<TaskScene> transform_scenes(const RigidTransform& g,
                                        const std::vector<TaskScene>& scenes);

/// A seed for sub-stream `index` of `seed` (splitmix64 of both), shared by the sim's samplers.
std::uint64_t stream_seed(std::uint64_t seed, std::uint64_t index);

}  // namespace handcentric::sim
