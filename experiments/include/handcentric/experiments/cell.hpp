#pragma once
// One cell of Table 1: a method with a head, trained on the first `demos` demos with one
// training seed, then scored on three scene sets. Its files are named by a hash of everything
// that determines the trained model, so a rerun (--resume, or another machine running the plan)
// finds finished work by name and redoes only what is missing.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "handcentric/policy/config.hpp"
#include "handcentric/sim/demos.hpp"
#include "handcentric/sim/difficulty.hpp"
#include "handcentric/sim/scenes.hpp"

namespace handcentric::experiments {

/// The three scene sets a cell is scored on.
///   id     : train-distribution scenes of the evaluation seed;
///   ood    : OOD (bottom-up) scenes of their own seed, independent of the id set;
///   paired : OOD scenes of the evaluation seed: scene i is a global transform of id scene i
///            with the same policy noise, so an SE(3)-equivariant policy scores exactly its id
///            success there (the equivariance result, not a generalization estimate).
enum class SceneSet { id, ood, paired };
inline constexpr SceneSet kSceneSets[] = {SceneSet::id, SceneSet::ood, SceneSet::paired};
std::string to_string(SceneSet set);
/// The scenes of `set` for the task's `difficulty`: the train distribution for id, the OOD one
/// for ood and paired (their seeds tell them apart, EvalSettings::seed).
sim::SceneDistribution scene_distribution(SceneSet set, const sim::Difficulty& difficulty);

struct EvalSettings {
  int trials = 100;
  std::uint64_t eval_seed = 100;  ///< id and paired scenes, and the policy noise there
  std::uint64_t ood_seed = 101;   ///< the independent OOD scenes
  /// The scene seed of `set` ("train" or "ood" distribution is implied by the set).
  std::uint64_t seed(SceneSet set) const { return set == SceneSet::ood ? ood_seed : eval_seed; }
  /// Cases per group of each model's pointwise audit (model_audit.hpp); 0: no audit (a run
  /// written before the audit column).
  int audit_cases = 200;
};

struct Cell {
  std::string method;  ///< methods.hpp name
  std::string head;    ///< flow, ddpm, cvae, c8ddpm
  int demos = 0;       ///< the first `demos` demos of the demo file
  std::uint64_t train_seed = 1;
  sim::TrainingData data;       ///< the demos' mirror images too, or not
  policy::PolicyConfig config;  ///< representation, head and the resolved step budget set
  std::string demo_digest;      ///< FNV-1a 64 (hex) of the demo file's bytes
  std::string hash;             ///< cell_hash(*this), set by make_cell

  /// "hand_centric/flow, 40 demos, train seed 1".
  std::string describe() const;
  std::string model_path() const;  ///< "models/<hash>.hcm"
  /// "results/<hash>.<set>-s<seed>-n<trials>-r<sim::kRolloutRulesVersion>.json"
  std::string result_path(SceneSet set, const EvalSettings& eval) const;
  /// "results/<hash>.audit-pointwise-n<eval.audit_cases>.json": `handcentric audit --model
  /// --view eye_in_hand --pointwise --json` of the model.
  std::string audit_path(const EvalSettings& eval) const;
  /// True when every result file of the cell (and its audit, when eval has one) is under `dir`.
  bool done(const EvalSettings& eval, const std::string& dir) const;
};

/// FNV-1a 64 of `bytes`, as 16 hex digits.
std::string digest(const std::string& bytes);

/// The cell's hash: digest of a canonical text of its demo digest, demo count, training seed,
/// the model file format and the full PolicyConfig (policy/config.hpp to_text).
std::string cell_hash(const Cell& cell);

/// The automatic training budget (Adam steps) for `demo_samples` scenes of demos trained on
/// under `data` with `head`, the one `handcentric train` and every table cell use: trainer.hpp's
/// training_budget(head, samples) of the samples with their mirror images (6 per sample, 3000
/// to 30000; the C8 heads count their 8x data up to 10000); the perturbed copies add no steps.
/// Measured on the tuning seeds (docs/EXPERIMENTS.md): with 4 copies 100 demos insert 1.00
/// after 10000 steps already, but relative actions need the 30000 (0.35 after 10000, 0.61
/// after 30000), and the hand-centric, relative and absolute rows get the same budget.
int automatic_steps(const sim::TrainingData& data, policy::HeadKind head, long long demo_samples);

/// A cell with its config from the library defaults (PolicyConfig{}), the method's
/// representation and the head, and `steps` Adam steps (0: automatic_steps), and `c8_centre` (x, y)
/// as the point c8ddpm rotates about (other heads ignore it); hash set.
Cell make_cell(const std::string& method, const std::string& representation,
               const std::string& head, int demos, std::uint64_t train_seed, long long demo_samples,
               const std::string& demo_digest, int steps = 0,
               const sim::TrainingData& data = sim::TrainingData(),
               std::array<double, 2> c8_centre = {0.0, 0.0});

}  // namespace handcentric::experiments
