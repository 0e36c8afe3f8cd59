#pragma once
// The analogue of Table 2 of "Guaranteed SE(3)-Equivariant Control via Hand-Centric Behavior
// Cloning" (blade insertion, real robot: hand-centric 26/30 in distribution, 5/5 out of
// distribution) on the simulated 3D blade insertion (sim/insert3d): flow policies with the
// hand-centric, relative and absolute action representations, trained on demos of train scenes
// and evaluated in closed loop on train, ood (the slot on its side) and random-se3 scenes.
//
// Seeds: the demos come from the train scenes of stream `seed`, the training from `seed`, and
// every evaluation set from the scenes of stream seed + 1 (disjoint from the demos' scenes).
// The three evaluation sets are paired: ood and random-se3 scene i are global transforms of
// train scene i (sim/insert3d/scenes.hpp), so an equivariant policy scores the same on all
// three, scene by scene, up to rounding.
//
//   DIR/table2.json  {"rows": [{"method", "demos", "trials", "train_success", "ood_success",
//                     "random_se3_success", "<set>_wilson95": [lo, hi], ...}], ...}
//   DIR/table2.md    the table beside the paper's Table 2 (table2_markdown)
//   DIR/table2.png, table2.svg   success per method and scene set, Wilson 95% bars
//   DIR/<method>.hcm, DIR/<method>_image.hcm   with save_models: each row's trained model, for
//                     `eval`, `render --rollout` and `audit --model` on the very policy of the row
// Every file is written atomically (write_file_atomically, write_png).
#include <cstdint>
#include <string>
#include <vector>

#include "handcentric/core/chunk_policy.hpp"
#include "handcentric/experiments/chart.hpp"
#include "handcentric/experiments/insert3d_image.hpp"
#include "handcentric/policy/config.hpp"
#include "handcentric/sim/draw.hpp"
#include "handcentric/sim/insert3d/demos.hpp"
#include "handcentric/sim/insert3d/rollout.hpp"
#include "handcentric/sim/insert3d/scenes.hpp"

namespace handcentric::experiments {

/// The 3D rollout settings of a trained model: its H and execute, and enough replans for
/// kMaxRolloutSteps steps.
sim::insert3d::RolloutOptions insert3d_rollout_options(const policy::PolicyConfig& config);
/// A rollout's step budget: the longest expert demo (200 poses) and a fifth more.
inline constexpr int kMaxRolloutSteps = 240;

/// Closed-loop outcomes on one scene set.
struct Insert3dCounts {
  int trials = 0;
  int success = 0;
  int collision = 0;
  int timeout = 0;
  int invalid = 0;
  int clipped = 0;  ///< commands clipped to the step limits
  double success_rate() const { return trials == 0 ? 0.0 : static_cast<double>(success) / trials; }
};

/// Rollouts of `policy` on scenes 0..trials-1 of `distribution` from stream `seed` (scene i's
/// noise stream stream_seed(seed, i)). Throws InvalidArgument for trials < 1 or bad options.
Insert3dCounts evaluate_insert3d(const ChunkPolicy& policy,
                                 const sim::insert3d::SceneDistribution& distribution, int trials,
                                 std::uint64_t seed, const sim::insert3d::RolloutOptions& options);

/// Demos of the expert on the first train scenes of stream `seed` that it solves, `count` of
/// them (it solves >= 99%; up to count + count / 5 + 10 scenes are tried). Throws
/// InvalidArgument for count < 1 or when too few scenes are solved.
std::vector<sim::insert3d::Demo> insert3d_train_demos(int count, std::uint64_t seed);

/// Noise injection into the training data (DART, Laskey et al. 2017): besides each demo's own
/// training scenes, `copies` copies of each in which the hand's poses (T_0 and its history) are
/// moved in the hand frame by a random delta (translation uniform in [-cm, cm]^3, rotation
/// vector uniform in [-deg, deg]^3), the corners re-observed from there and the chunk left as the
/// demo's next K poses: the policy sees what to do when it is a little off the demonstrated path,
/// which the demos alone never show. Deltas act in the hand frame, so the data stays invariant in
/// distribution and the hand-centric policy stays equivariant (Theorem 1 holds for any data).
struct Perturbation {
  int copies = 0;
  double max_cm = 0.15;
  double max_deg = 1.0;
  /// Throws InvalidArgument for copies outside 0..100 or a negative or non-finite size, naming
  /// the value by its flag (`flag` + "-copies", e.g. --perturb-copies).
  void validate(const std::string& flag = "--perturb") const;
};

/// The noise injection of Table 2's rows that see `observation`: two copies of every training
/// scene, the hand moved by up to 0.15 cm per axis and turned by up to 1 deg (key points) or
/// 5 deg (images). Each was chosen on the tuning seeds (--seed 1000): the key-point rows gain
/// from the copies (relative 0.10 -> 0.66, hand-centric 0.98 -> 1.00, docs/EXPERIMENTS.md); the
/// hand-centric image policy turns too late on the scenes that start with the largest yaw, and
/// copies turned by up to 5 deg fix that (28/30 -> 29/30 on every set at --seed 1000, 26/30 ->
/// 30/30 at --seed 2000, losing no scene; docs/SIM.md, "The defaults and the measurements
/// behind them").
Perturbation insert3d_default_perturbation(policy::ObservationKind observation);

/// The training scenes of `demos` (H, K) and their perturbed copies (demo after demo), drawn
/// from the stream `seed`.
std::vector<Scene> insert3d_training_data(const std::vector<sim::insert3d::Demo>& demos, int H,
                                          int K, const Perturbation& perturbation,
                                          std::uint64_t seed);

struct Table2Options {
  int demos = 100;
  int trials = 100;
  std::string out = "table2";
  std::uint64_t seed = 1;
  int jobs = 0;   ///< cores: key-point trainings at once, an image training's threads
                  ///< (one image row at a time); 0: one per hardware thread
  int steps = 0;  ///< Adam steps per policy; 0: automatic (the key-point rows: the library's
                  ///< budget; the image rows: Insert3dImageSettings::steps)
  std::vector<std::string> methods = {"hand_centric", "relative", "absolute"};
  /// What the policies see, one set of rows each: the key points (insert3d_key_points.hpp)
  /// and/or the hand camera's depth image through a CNN trained end to end (insert3d_image.hpp).
  std::vector<policy::ObservationKind> observations = {policy::ObservationKind::key_points};
  /// The image rows' camera and encoder.
  Insert3dImageSettings image;
  /// The key-point rows' and the image rows' noise injection (insert3d_default_perturbation).
  Perturbation perturbation = insert3d_default_perturbation(policy::ObservationKind::key_points);
  Perturbation image_perturbation = insert3d_default_perturbation(policy::ObservationKind::image);
  const Perturbation& perturbation_for(policy::ObservationKind observation) const {
    return observation == policy::ObservationKind::image ? image_perturbation : perturbation;
  }
  bool quiet = false;
  /// Also write each row's model (table2_model_file).
  bool save_models = false;

  /// Throws InvalidArgument naming the bad value and the fix (demos outside 1..1000, trials
  /// outside 1..100000, jobs < 0, steps < 0, no method or an unknown representation, no
  /// observation, image settings that make no camera or encoder).
  void validate() const;
};

struct Table2Row {
  std::string method;  ///< the representation: hand_centric, relative or absolute
  policy::ObservationKind observation = policy::ObservationKind::key_points;
  std::string image;  ///< image rows: the camera and encoder, e.g. "depth, 32 x 24, 70 deg, ..."
  int demos = 0;
  std::uint64_t seed = 0;
  int steps = 0;               ///< Adam steps run
  Perturbation perturbation;   ///< the noise injection of its training data
  double train_seconds = 0.0;  ///< wall-clock time of the training
  Insert3dCounts train, ood, random_se3;
};

/// A row's method as its tables and charts name it: "hand_centric", "hand_centric (image)".
std::string table2_row_label(const Table2Row& row);

/// The file name of a row's model in DIR with Table2Options::save_models: "<method>.hcm" for
/// the key-point rows, "<method>_image.hcm" for the image rows.
std::string table2_model_file(const std::string& method, policy::ObservationKind observation);

/// The training scenes of the rows that see `observation`: `demos` and their perturbed copies
/// (options.perturbation_for(observation)), from the stream options.seed.
std::vector<Scene> table2_training_data(const Table2Options& options,
                                        const std::vector<sim::insert3d::Demo>& demos,
                                        policy::ObservationKind observation);

/// Trains and evaluates every method for every observation (options.jobs at a time), writes
/// DIR/table2.json, .md, .png and .svg (DIR created when missing) and returns the rows in method
/// order.
std::vector<Table2Row> run_table2(const Table2Options& options);

/// The rows as the table2.json document.
std::string table2_json(const std::vector<Table2Row>& rows);
/// table2.md: what the run was (demos, seeds, trials, each kind of row's noise injection and
/// camera), then table2_table (results_page.hpp) through the page's Markdown renderer.
std::string table2_markdown(const std::vector<Table2Row>& rows);
/// Success per method and scene set as grouped bars with Wilson 95% intervals, the paper's
/// hand-centric numbers as ticks (chart.hpp). Throws InvalidArgument for no rows.
BarChart table2_chart(const std::vector<Table2Row>& rows);
/// table2_chart as an RGB image.
sim::Image draw_table2(const std::vector<Table2Row>& rows, int width = 900, int height = 520);

}  // namespace handcentric::experiments
