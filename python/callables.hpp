#pragma once
// The Python callables under audit, as the library's batch interfaces (props/batch.hpp): a
// representation (actions, observation, decode functions) and a whole policy. Called one scene
// at a time (the arrays of one scene) or, when the caller gave batch_size, on stacked arrays
// with a leading batch axis; NumPy arrays or torch tensors (ArrayKind). The library's
// BatchedRepresentation / BatchedPolicy around them cache the answers and form the batches.
//
// A Python exception inside a callable leaves as PythonCallError, and so does a KeyboardInterrupt
// pending before a call (a signal reaches Python only when PyErr_CheckSignals() runs: every call
// checks first, so Ctrl-C stops an audit within one call or one batch).
#include <pybind11/pybind11.h>

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "named_outputs.hpp"
#include "handcentric/core/pose_format.hpp"
#include "handcentric/props/transport/batch.hpp"
#include "handcentric/props/observation/camera_rig.hpp"

namespace handcentric::python {

/// How a callable is called.
struct CallOptions {
  bool stacked = false;  ///< stacked arrays (B, ...) instead of one scene's
  ArrayKind arrays;      ///< NumPy arrays or torch tensors
  bool extras = false;   ///< pass extra_poses= and scalars= keywords (the audit asked for some)
  /// When set: pass images={view: (C, h, w) or (B, C, h, w) float32} rendered by this rig.
  std::shared_ptr<const props::CameraRig> cameras;
  /// A policy's own random draws made alike on both sides (handcentric/_rng.py): "" (off),
  /// "torch", "numpy" or "generator"; seeded before each call from rng_seed and the row's noise.
  std::string rng;
  std::uint64_t rng_seed = 0;
  /// Called with no arguments before every call of a policy (e.g. LeRobot's policy.reset), or None.
  py::object reset = py::none();
  /// A policy's layout of the poses it returns (action_format=) and of those it is given, the
  /// history and the extra poses (state_format=): core/pose_format.hpp.
  PoseFormat action_format, state_format;
  /// outputs=: the entries of a policy's dict result (named_outputs.hpp), and the one this
  /// callable hands the checks ("" when the policy returns its chunk alone).
  std::vector<NamedOutput> outputs;
  std::string output;
  /// The closed loop's pose output, when it is not `output`: the first pose of its chunk goes
  /// ahead of `output`'s chunk, so that the loop executes it and compares `output`
  /// (props::ClosedLoopOptions::compared_from).
  std::string executed_output;
  /// hands=: the hands' names, the first the audit's own hand (hands.hpp); empty: one hand.
  std::vector<std::string> hands;
  /// The other hands' histories are recorded (observations=), not drawn: read them from the
  /// scene's "hand:h@-k" poses (props/observation/hands.hpp).
  bool hands_recorded = false;
  /// Told the number of observations of every call before it is made (the audit's progress
  /// line, options.hpp's ProgressLine), or empty.
  std::function<void(std::size_t)> asked;
};

/// images={view: array} as a callable receives them for `scenes` (one: (C, h, w); stacked:
/// (B, C, h, w) float32), rendered by options.cameras.
py::dict images_of(const std::vector<const Scene*>& scenes, const CallOptions& options);

/// The name a report shows for a callable: a function's qualified name, else its class's (an
/// object with __call__, e.g. a torch module), so that the name does not change between runs.
std::string callable_name(const py::object& fn);

/// A representation written in Python: actions(history, chunk, hand_points, world_points) and,
/// optionally, observation(history, hand_points, world_points) and decode(actions, history,
/// hand_points, world_points) -> (K, 4, 4) (decode is always called one scene at a time).
class PythonRepresentation final : public props::BatchRepresentation {
 public:
  PythonRepresentation(py::object actions, py::object observation, py::object decode,
                       CallOptions options);
  std::string name() const override { return name_; }
  bool has_observation() const override { return !observation_.is_none(); }
  std::vector<Eigen::VectorXd> encode_actions_batch(
      const std::vector<const Scene*>& scenes) const override;
  std::vector<Eigen::VectorXd> encode_observation_batch(
      const std::vector<const Scene*>& scenes) const override;
  bool can_decode() const override { return !decode_.is_none(); }
  std::vector<RigidTransform> decode_in_scene(const Eigen::VectorXd& actions,
                                              const Scene& observation) const override;

 private:
  std::vector<Eigen::VectorXd> encode(const py::object& fn, bool with_chunk,
                                      const std::vector<const Scene*>& scenes,
                                      const std::string& what) const;
  py::object actions_, observation_, decode_;
  CallOptions options_;
  std::string name_;
};

/// A whole policy written in Python: policy(history, hand_points, world_points, noise) -> the
/// world-frame chunk T_1..T_K, (K, 4, 4); stacked: (B, K, 4, 4) for noise (B, d). The noise is
/// its only randomness.
class PythonPolicy final : public props::BatchPolicy {
 public:
  PythonPolicy(py::object policy, Eigen::Index noise, CallOptions options);
  std::string name() const override { return name_; }
  Eigen::Index noise_dimension() const override { return noise_; }
  std::vector<std::vector<RigidTransform>> act_batch(
      const std::vector<const Scene*>& observations,
      const std::vector<const Eigen::VectorXd*>& noises) const override;
  std::optional<std::vector<std::string>> last_draws() const override;
  void watch_draws(bool on) const override;

 private:
  /// One call of the callable on these rows, after reset() and the seeding of options.rng.
  std::vector<std::vector<RigidTransform>> call_once(
      const std::vector<const Scene*>& observations,
      const std::vector<const Eigen::VectorXd*>& noises) const;
  py::object policy_;
  Eigen::Index noise_;
  CallOptions options_;
  std::string name_;
  py::object rng_module_;  ///< handcentric._rng: the generators' snapshots and seeding
  mutable bool watching_ = false;
  mutable std::vector<std::string> draws_;  ///< generators advanced since watch_draws(true)
};

}  // namespace handcentric::python
