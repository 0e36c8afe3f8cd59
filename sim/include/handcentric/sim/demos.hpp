#pragma once
// Demonstrations: expert trajectories of the 2D insertion task, their file format, and the
// training scenes a behavior-cloning policy learns from (Sec. 4.2).
//
// File format (docs/SIM.md): JSON Lines. Line 1 is a header
//   {"format": "handcentric-demos", "version": 1, "task": "peg2d", "count": N, "clearance": c}
// (a header without "task" is peg2d; a file of another task, such as insert3d/demos.hpp's, is
// refused with a message naming both tasks)
// then one line per demo (record 1..N):
//   {"world_T_hole": P, "world_T_hand": [P, P, ...]}
// where each pose P is a 3x4 matrix [[r00, r01, r02, x], [r10, r11, r12, y], [r20, r21, r22, z]]
// (row-major, shortest round-trip decimal, so a load gives back the same bits).
//
// Bounded input: load_demos refuses a file that passes one of the limits below with
// InvalidDemoFile, before it allocates for what is over the limit. Its memory is at most one line
// (and that line's JSON tree, ~20 bytes per byte of the line) plus the poses it keeps, so a
// hostile or broken file costs at most a few hundred MB (tests/sim/test_demo_limits.cpp measures
// it).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/scene.hpp"
#include "handcentric/sim/geometry.hpp"

namespace handcentric::sim {

/// A demo file that cannot be read: missing, not JSON Lines, wrong shapes, NaN, a non-rigid or
/// non-planar pose, a truncated file. The message names the file, the record and the value.
class InvalidDemoFile : public Error {
 public:
  using Error::Error;
};

/// What load_demos accepts. An expert demo of the task has ~50-300 poses (~250 bytes each), a
/// data set of Table 1 at most 100 demos: the defaults are far above real files. Tests pass
/// smaller limits to reach each one cheaply.
struct DemoFileLimits {
  /// Bytes of one line, without its newline: 4 MiB, ~16000 poses.
  std::size_t max_line_bytes = std::size_t{4} << 20;
  /// Containers nested in one line: a record is 4 deep (record, pose list, pose, row).
  int max_json_depth = 8;
  /// Demos the header may announce.
  std::size_t max_demos = 100'000;
  /// Poses in one demo.
  std::size_t max_poses_per_demo = 10'000;
  /// Poses in the whole file (~200 MB once loaded).
  std::size_t max_poses = 2'000'000;
};

struct Demo {
  RigidTransform world_T_hole;               ///< the hole (planar)
  std::vector<RigidTransform> world_T_hand;  ///< the hand at each control step; [0] = start
};

/// Reads and validates a demo file (format above). Throws InvalidDemoFile naming the record, also
/// for a file over one of the DemoFileLimits (naming the limit).
std::vector<Demo> load_demos(const std::string& path,
                             const DemoFileLimits& limits = DemoFileLimits());

/// The task a demo file records in its header ("peg2d" for a header without one, written before
/// the 3D task), reading the header line only. Throws InvalidDemoFile as load_demos does for a
/// missing file or a bad header.
std::string demo_file_task(const std::string& path,
                           const DemoFileLimits& limits = DemoFileLimits());

/// The 2D task's hole a demo file records in its header ("clearance"; the paper's 0.1 for a
/// header without one), reading the header line only: the hole its recovery copies must clear.
/// Throws InvalidDemoFile as load_demos does, and for a clearance outside (0, kPegWidth).
PegHoleGeometry demo_file_geometry(const std::string& path,
                                   const DemoFileLimits& limits = DemoFileLimits());

/// load_demos on a file's bytes already in memory (received, embedded, or a fuzzer's input);
/// `source` names them in errors as the path would. Same checks, limits and errors.
std::vector<Demo> parse_demos(const std::string& bytes, const std::string& source,
                              const DemoFileLimits& limits = DemoFileLimits());

/// Writes `demos` atomically (a temporary file beside `path`, then rename). Throws
/// InvalidArgument for an empty or non-planar demo, Error when the file cannot be written.
void save_demos(const std::string& path, const std::vector<Demo>& demos,
                const PegHoleGeometry& geometry = PegHoleGeometry());

/// The eye-in-hand observation of Sec. 4.2: the two corners of the hole's opening
/// (left, then right) in the frame of the hand at world_T_hand.
std::vector<Eigen::Vector3d> eye_in_hand_points(
    const RigidTransform& world_T_hole, const RigidTransform& world_T_hand,
    const PegHoleGeometry& geometry = PegHoleGeometry());

/// One Scene per control step t = 0..T-1 of `demo`: history T_t, T_{t-1}, ..., T_{t-H} (the
/// first pose repeated before the start), chunk T_{t+1}..T_{t+K} (the last pose repeated after
/// the end), hand_points = eye_in_hand_points at T_t, no world points.
/// Throws InvalidArgument for H < 0, K < 1 or an empty demo.
std::vector<Scene> training_scenes(const Demo& demo, int H, int K,
                                   const PegHoleGeometry& geometry = PegHoleGeometry());

/// The training scenes of the first `max_demos` demos (0: all of them), demo after demo: what a
/// behavior-cloning policy with history H and chunk K learns from. Throws InvalidArgument for
/// max_demos < 0 or more than demos.size() (naming both and the fix), and as above.
std::vector<Scene> training_scenes(const std::vector<Demo>& demos, int H, int K, int max_demos = 0,
                                   const PegHoleGeometry& geometry = PegHoleGeometry());

/// The demo reflected about its hole's axis (the hole frame's y axis): every hand pose
/// hole_T_hand = planar(theta, x, y) becomes planar(-theta, -x, y). The peg, the hole and the
/// start-pose range are symmetric about that axis (docs/SIM.md), so the result is another
/// collision-free insertion from a start pose of the same distribution: training data the
/// task's own symmetry gives for free. Throws InvalidArgument for an empty or non-planar demo.
Demo mirrored_about_hole_axis(const Demo& demo);

/// `demos` followed by mirrored_about_hole_axis of each.
std::vector<Demo> with_mirrored_demos(const std::vector<Demo>& demos);

/// What a policy of this task trains on besides its demos' own scenes.
struct TrainingData {
  /// Also train on each demo's mirror image (mirrored_about_hole_axis). On by default: on the
  /// tuning seeds, hand-centric flow at 40 demos inserts 0.91 of the time with it and 0.74
  /// without at the same number of steps (docs/EXPERIMENTS.md).
  bool mirror = true;
  /// Perturbed copies of each training sample (0: none), each a relabelled recovery: the hand
  /// moved off the demo by a random planar offset (uniform in +-offset_cm along x and y and
  /// +-offset_deg in angle, in the hole's frame), the chunk returning to the demo's poses over
  /// `recovery_steps` steps (the offset shrinks linearly to 0), the observation seen from the
  /// moved hand. A copy whose pose or motion touches the hole is dropped. Like mirror images, it
  /// uses no expert call: the demo's own future is the label. 4 by default: on the tuning seeds,
  /// hand-centric flow at 10 demos inserts 0.98 of the time with them and 0.03 without
  /// (docs/EXPERIMENTS.md). perturbation_seed is the training run's seed (train --seed).
  int perturbed_copies = 4;
  double offset_cm = 1.0;
  double offset_deg = 10.0;
  int recovery_steps = 4;
  std::uint64_t perturbation_seed = 1;
  /// The samples of `demo_samples` demo scenes with their mirror images, the count a training
  /// budget grows with (the perturbed copies, which vary those samples, are not counted).
  long long samples(long long demo_samples) const {
    return mirror ? 2 * demo_samples : demo_samples;
  }
  /// Throws InvalidArgument naming the field for a negative count or offset, or recovery_steps < 1.
  void validate() const;
  /// Every field as "name=value" lines, in a fixed order: what a cache key of a model trained
  /// on this recipe must include.
  std::string to_text() const;
};

/// The training scenes of the first `max_demos` demos (0: all) and, with data.mirror, of their
/// mirror images after them. Throws as training_scenes.
std::vector<Scene> training_scenes(const std::vector<Demo>& demos, int H, int K, int max_demos,
                                   const TrainingData& data,
                                   const PegHoleGeometry& geometry = PegHoleGeometry());

}  // namespace handcentric::sim
