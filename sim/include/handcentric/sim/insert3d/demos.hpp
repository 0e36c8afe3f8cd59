#pragma once
// Demonstrations of the 3D blade insertion: their file and the training scenes a
// behavior-cloning policy learns from.
//
// File format: the 2D task's JSON Lines (sim/demos.hpp, docs/SIM.md) with the task named in the
// header and full SE(3) poses:
//   {"format": "handcentric-demos", "version": 1, "task": "insert3d", "count": N,
//    "clearance_per_side": c}
//   {"world_T_slot": P, "world_T_hand": [P, P, ...]}          (one line per demo)
// Each file records its task: the 2D loader refuses an insert3d file and this one refuses a 2D
// file (whose header says "peg2d", or nothing in files written before the 3D task), naming both.
#include <string>
#include <vector>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/scene.hpp"
#include "handcentric/sim/demos.hpp"
#include "handcentric/sim/insert3d/geometry.hpp"

namespace handcentric::sim::insert3d {

struct Demo {
  RigidTransform world_T_slot;
  std::vector<RigidTransform> world_T_hand;  ///< the hand at each control step; [0] = start
};

/// Writes `demos` atomically. Throws InvalidArgument for an empty demo or a bad geometry, Error
/// when the file cannot be written.
void save_demos(const std::string& path, const std::vector<Demo>& demos,
                const BladeSlotGeometry& geometry = BladeSlotGeometry());

/// Reads and validates a demo file of this task, within `limits`. Throws InvalidDemoFile naming
/// the file, the record and the value (for a 2D file: both tasks and the option that reads it).
std::vector<Demo> load_demos(const std::string& path,
                             const DemoFileLimits& limits = DemoFileLimits());

/// One Scene per control step of `demo` (as the 2D task's training_scenes): history H, chunk K,
/// hand_points = the opening's four corners in the hand frame at that step.
std::vector<Scene> training_scenes(const Demo& demo, int H, int K,
                                   const BladeSlotGeometry& geometry = BladeSlotGeometry());

/// The training scenes of the first `max_demos` demos (0: all of them).
std::vector<Scene> training_scenes(const std::vector<Demo>& demos, int H, int K, int max_demos = 0,
                                   const BladeSlotGeometry& geometry = BladeSlotGeometry());

}  // namespace handcentric::sim::insert3d
