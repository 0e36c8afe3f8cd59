#pragma once
// Workspace: the box, in the world frame, where a policy is meant to work. A policy whose
// normalizer was fit on +-1 m, or that clips world positions to its cell, can only be asked
// about symmetry inside its cell: with a workspace, the audit draws every scene inside the box
// and every g so that g * scene stays inside it too (generators.hpp), and each verdict says so.
// A policy that clips to its box is then equivariant within it and not beyond, and the audit
// shows both (tests/props/test_workspace.cpp).
#include <Eigen/Core>
#include <string>

#include "handcentric/core/scene.hpp"
#include "handcentric/props/group.hpp"

namespace handcentric::props {

struct Workspace {
  Eigen::Vector3d min = Eigen::Vector3d::Constant(-1.0);  ///< metres, world frame
  Eigen::Vector3d max = Eigen::Vector3d::Constant(1.0);

  /// Throws InvalidArgument naming the value and the fix: a non-finite corner, or a side that is
  /// not longer than 1 mm.
  void validate() const;

  /// "x0,y0,z0,x1,y1,z1" (the CLI's --workspace), validated.
  static Workspace parse(const std::string& text);

  /// Every world-frame position of `scene`, that of g * scene included when it is checked: the
  /// history's and the chunk's, the world points, the extra poses' (the eye-in-hand points are
  /// in the hand frame and go where the hand goes).
  bool contains(const Scene& scene) const;

  /// "[-1, 1] x [-1, 1] x [0, 1] m".
  std::string describe() const;

  /// The note each verdict decided inside the workspace carries.
  std::string verdict_note() const;

  /// The room `group`'s transforms have in the box (generators.hpp's case_in_workspace): for
  /// rotation, the largest ball about the origin inside it; for c8, the largest cylinder about
  /// world z; else the half of its shortest side. Throws InvalidArgument naming the box, the
  /// group and the fix when there is none (rotation: the origin not inside; c8: the z axis not).
  double room_for(Group group) const;
};

}  // namespace handcentric::props
