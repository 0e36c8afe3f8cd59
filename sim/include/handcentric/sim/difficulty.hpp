#pragma once
// The 2D task's difficulty: the two knobs that decide how precise an absolute-coordinate policy
// must be (issue 26 item 2, docs/TABLE1.md "Where the absolute rows work").
//
//   workspace_cm : the side of the square the hole's opening is drawn in, [-w/2, w/2]^2. The
//                  paper's task, and the default, is 100 cm. An absolute policy must place the
//                  peg to within the clearance anywhere in it, so its error scales with the
//                  span of the coordinates it reads; a hand-centric policy never sees where the
//                  hole is (Theorem 1), so the workspace cannot change what it does.
//   clearance_cm : the hole's inner width minus the peg's (PegHoleGeometry::clearance), 0.1.
//
// Demos, evaluation scenes and the collision checker of one run share one Difficulty; the demo
// file records the clearance, and table1's cells.json records both.
#include <string>

#include "handcentric/sim/geometry.hpp"
#include "handcentric/sim/scenes.hpp"

namespace handcentric::sim {

struct Difficulty {
  double workspace_cm = 2.0 * kWorkspaceHalfWidth;
  double clearance_cm = kDefaultClearance;

  /// Throws InvalidArgument naming the value and the range: workspace in [1, 1000] cm, clearance
  /// in (0, kPegWidth) cm, both finite.
  void validate() const;
  bool is_default() const;
  /// `distribution` with its opening drawn in this workspace.
  SceneDistribution apply(SceneDistribution distribution) const;
  PegHoleGeometry geometry() const;
  /// "workspace 50 cm, clearance 0.1 cm".
  std::string describe() const;
};

}  // namespace handcentric::sim
