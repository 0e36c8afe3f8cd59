#pragma once
// Where `eval` and `render` get the policy they roll out: a trained model file (--model) or a
// scripted policy of the sim by name (--policy expert|straight|hold).
#include <memory>
#include <string>
#include <vector>

#include "handcentric/core/chunk_policy.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/sim/insert3d/camera.hpp"
#include "handcentric/sim/insert3d/rollout.hpp"
#include "handcentric/sim/rollout.hpp"

namespace handcentric::apps {

/// A policy and the rollout settings it needs.
struct LoadedPolicy {
  std::unique_ptr<ChunkPolicy> policy;
  /// The rollout's observation history and executed poses: the H a model was trained with (a
  /// rollout with another H would hand it observations of the wrong shape) and its execute, the
  /// sim's defaults for scripted policies.
  sim::RolloutOptions rollout_options;
};

/// The model in `model_path` when it is not empty, else the scripted policy `scripted_name`.
/// Throws a typed error naming the file or the name when neither can be had.
/// `overrides` apply to a model only.
LoadedPolicy load_chunk_policy(const std::string& model_path, const std::string& scripted_name,
                               const policy::SamplingOverrides& overrides = {});

/// The same for the 3D task: the model in `model_path` (which must be an insert3d model, else
/// TaskMismatch) with its H, execute and replans, or the closed-loop 3D expert when it is empty.
struct LoadedInsert3dPolicy {
  std::shared_ptr<const ChunkPolicy> policy;
  sim::insert3d::RolloutOptions rollout_options;
  /// The camera the frames of a rollout are drawn with: an image model's own (its size and
  /// field of view), else the task's.
  sim::insert3d::DepthCamera camera;
  /// The cameras an image model sees through (its rig: `camera`, and its mirror for a
  /// two-camera model), else the task's one.
  std::vector<sim::insert3d::DepthCamera> rig{sim::insert3d::DepthCamera{}};
  /// An image model that sees surface normals: the frames show them beside the depth.
  bool normals = false;
};
LoadedInsert3dPolicy load_insert3d_policy(const std::string& model_path,
                                          const policy::SamplingOverrides& overrides = {});

}  // namespace handcentric::apps
