#pragma once
// RapidCheck generators for rotations, rigid transforms and scenes.
//
// Rotations are Haar-uniform (a uniform axis and an angle by the inverse CDF of Haar's angle
// law), mixed with the edge cases where SO(3) code breaks: the identity, angles of 1e-12, angles
// within 1e-9 of pi and exactly pi. Every generator shrinks toward simpler values (smaller
// numbers, fewer poses); rotations toward the identity, the smallest angle that still fails.
#include <rapidcheck.h>

#include <memory>
#include <optional>

#include <string>
#include <vector>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/rotation.hpp"
#include "handcentric/core/scene.hpp"
#include "handcentric/props/group.hpp"
#include "handcentric/props/observation/workspace.hpp"

namespace handcentric::props {

struct RecordedObservations;  // observation/recorded.hpp

/// An integer uniform in [low, high) in every case of a check, shrinking toward low. Every draw
/// of the audit goes through it, not through rc::gen::inRange: RapidCheck scales inRange's range
/// with the case's size, which grows from 0 with the case number, so a check's first cases
/// would draw only near `low` (lengths near 1 cm, rotations near the identity, a recorded file's
/// first scenes, the identity of C8), and the cases would not be draws of one law, which every
/// verdict's arithmetic (detectable_frequency, the tests' levels) assumes.
template <class T>
rc::Gen<T> uniform_integer(T low, T high) {
  return rc::gen::resize(rc::kNominalSize, rc::gen::inRange<T>(low, high));
}

/// A Haar-uniform rotation (no edge cases); shrinks toward the identity.
rc::Gen<Rotation> haar_rotation();

/// Haar-uniform rotations mixed with edge cases (identity, 1e-12, pi - 1e-9, pi): 1 in 5 is an edge
/// case.
rc::Gen<Rotation> rotation();

/// A rotation whose angle is within 1e-10 of pi (about a Haar-random axis).
rc::Gen<Rotation> rotation_near_pi();

/// A rotation whose angle is at most 1e-10.
rc::Gen<Rotation> rotation_near_identity();

/// A translation with each coordinate in [-max_abs, max_abs].
rc::Gen<Eigen::Vector3d> translation(double max_abs);

/// An element of `group`, including that group's edge cases (identity, tiny angles, angles near
/// pi where the group has them, zero and 1e3 m translations where it has translations).
/// Translations are otherwise of log-uniform length in [0.01, 10] m, in a uniform direction.
/// `planar`: translations in the plane z = 0 (the 2D task's); rotation and se3 have no planar
/// form (they tilt the plane) and are generated as without it.
rc::Gen<RigidTransform> group_element(Group group, bool planar = false);

/// Scene sizes.
struct SceneShape {
  int min_history = 0, max_history = 4;  ///< H
  int min_chunk = 1, max_chunk = 32;     ///< K
  int max_world_points = 3;
  int max_hand_points = 3;
  int min_world_points =
      0;  ///< above 0, the count is drawn in [min, max] (a fixed count: min = max)
  int min_hand_points = 0;
  /// Named world-frame poses to generate (e.g. "start"): random poses that move with g.
  std::vector<std::string> extra_pose_names;
  /// Named scalars to generate (e.g. "gripper"): numbers in [-1, 1] that g leaves alone.
  std::vector<std::string> scalar_names;
  /// The 2D task's scenes: every pose a rotation about z at z = 0, every step in the plane,
  /// every point at z = 0; the checks then draw planar translations and perturb in the plane.
  bool planar = false;
  /// When set, the checks draw their cases by case_in_workspace() instead of scene() and
  /// group_element().
  std::optional<Workspace> workspace;
  /// When set, the checks draw their scenes from these instead (recorded_case()); the sizes
  /// above are then the data's, except that a shape with no world points (the eye-in-hand
  /// view) drops the recorded world points.
  std::shared_ptr<const RecordedObservations> recorded;
};

/// A scene at a length scale lambda drawn log-uniformly in [0.01, 10] m: a random start pose
/// lambda from the origin, a smooth but rotating chunk (a constant random twist per step, up to
/// 0.01 lambda and 0.3 rad per axis; one time in eight none, a hand at rest with T_k = T_0), a
/// history the same way backwards, eye-in-hand points
/// within 0.1 lambda and world points within lambda per coordinate, and the extra poses (within
/// 10 m) and scalars the shape names; all of it in the plane z = 0 when shape.planar.
rc::Gen<Scene> scene(SceneShape shape = {});

/// A scene inside `workspace` and a g in `group` that keeps it there (every world-frame position
/// of g * scene inside too, Workspace::contains). The scene is one of scene(shape), scaled about
/// its centre so that it has room to move, and placed: anywhere in the box for the groups with
/// translations, whose g then gets a translation drawn from those that keep g * scene inside;
/// within the largest ball about the origin inside the box for rotation, and within the largest
/// cylinder about world z for c8 (g has no translation there). Throws InvalidArgument when the
/// box leaves a rotation group no room (rotation: the origin not inside the box; c8: the z axis
/// not inside it).
rc::Gen<std::pair<Scene, RigidTransform>> case_in_workspace(const SceneShape& shape, Group group,
                                                            const Workspace& workspace);

/// A recorded observation (shape.recorded, drawn uniformly; shrinking goes to the first) and a g
/// in `group`. With shape.workspace, g is drawn as without one and then turned back toward the
/// identity (its angle halved, or for c8 one step of 45 degrees at a time) until a translation
/// of its group keeps every world position of g * o inside the box; that translation is then
/// drawn uniformly among those. The observations must lie inside the box
/// (RecordedObservations::require_inside), so the identity always does.
rc::Gen<std::pair<Scene, RigidTransform>> recorded_case(const SceneShape& shape, Group group);

/// The scene a check starts from, without g: a recorded observation (shape.recorded), else one
/// inside shape.workspace, else scene(shape). Injectivity draws its scenes so.
rc::Gen<Scene> shaped_scene(const SceneShape& shape);

}  // namespace handcentric::props
