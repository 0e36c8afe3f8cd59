#pragma once
// The demo file format shared by the tasks (private to sim's sources): JSON Lines, a header that
// names the task, then one record per demo {<object key>: pose, "world_T_hand": [pose, ...]}.
// Reading is bounded by DemoFileLimits (see demos.hpp); a file of another task is refused with
// a message that names both tasks and the option that reads it.
#include <algorithm>
#include <string>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/scene.hpp"
#include "handcentric/sim/demos.hpp"

namespace handcentric::sim::detail {

/// What differs between the tasks' files.
struct DemoFileTask {
  std::string name;           ///< "peg2d" (also a header without "task") or "insert3d"
  std::string object_key;     ///< the record's object pose: "world_T_hole" or "world_T_slot"
  bool planar = false;        ///< every pose must be planar (the 2D task)
  std::string clearance_key;  ///< the header's clearance entry
};

/// One demo: the object's pose and the hand at each control step.
struct DemoRecord {
  RigidTransform world_T_object;
  std::vector<RigidTransform> world_T_hand;
};

/// Writes atomically. Throws InvalidArgument for an empty demo or, for a planar task, a
/// non-planar pose; Error when the file cannot be written.
void save_demo_records(const std::string& path, const DemoFileTask& task, double clearance,
                       const std::vector<DemoRecord>& demos);

/// Reads and validates, within `limits`. Throws InvalidDemoFile naming the file, the record and
/// the value (a file of another task names both tasks).
std::vector<DemoRecord> load_demo_records(const std::string& path, const DemoFileTask& task,
                                          const DemoFileLimits& limits);

/// load_demo_records on a file's bytes in memory; `source` names them in errors as a path would.
std::vector<DemoRecord> parse_demo_records(const std::string& bytes, const std::string& source,
                                           const DemoFileTask& task, const DemoFileLimits& limits);

/// One Scene per control step t of a demo: history T_t..T_{t-H} (the first pose repeated before
/// the start), chunk T_{t+1}..T_{t+K} (the last pose repeated after the end), hand_points =
/// points_at(T_t). Throws InvalidArgument for H < 0, K < 1 or an empty demo.
template <typename PointsAt>
std::vector<Scene> demo_training_scenes(const std::vector<RigidTransform>& world_T_hand, int H,
                                        int K, const PointsAt& points_at) {
  if (H < 0) throw InvalidArgument("history length H must be >= 0, got " + std::to_string(H));
  if (K < 1) throw InvalidArgument("chunk length K must be >= 1, got " + std::to_string(K));
  if (world_T_hand.empty()) throw InvalidArgument("training_scenes: the demo has no hand pose");
  const int T = static_cast<int>(world_T_hand.size());
  const auto pose = [&](int t) {
    return world_T_hand[static_cast<std::size_t>(std::clamp(t, 0, T - 1))];
  };
  std::vector<Scene> scenes;
  scenes.reserve(static_cast<std::size_t>(T));
  for (int t = 0; t < T; ++t) {
    Scene scene;
    for (int h = 0; h <= H; ++h) scene.world_T_hand_history.push_back(pose(t - h));
    for (int k = 1; k <= K; ++k) scene.world_T_hand_chunk.push_back(pose(t + k));
    scene.hand_points = points_at(pose(t));
    scenes.push_back(std::move(scene));
  }
  return scenes;
}

/// The training scenes of the first `max_demos` demos (0: all), demo after demo, from
/// scenes_of(demo). Throws InvalidArgument for max_demos < 0 or more than demos.size().
template <typename DemoType, typename ScenesOf>
std::vector<Scene> demos_training_scenes(const std::vector<DemoType>& demos, int max_demos,
                                         const ScenesOf& scenes_of) {
  if (max_demos < 0) {
    throw InvalidArgument("the number of demos to train on must be >= 0 (0 = all), got " +
                          std::to_string(max_demos));
  }
  if (max_demos > static_cast<int>(demos.size())) {
    throw InvalidArgument("asked to train on " + std::to_string(max_demos) + " demos but only " +
                          std::to_string(demos.size()) + " are given: ask for at most that many");
  }
  const std::size_t used = max_demos == 0 ? demos.size() : static_cast<std::size_t>(max_demos);
  std::vector<Scene> scenes;
  for (std::size_t i = 0; i < used; ++i) {
    for (Scene& scene : scenes_of(demos[i])) scenes.push_back(std::move(scene));
  }
  return scenes;
}

}  // namespace handcentric::sim::detail
