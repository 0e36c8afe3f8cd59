#pragma once
// The classifier: for one representation (or flow target), which groups leave each component
// invariant, pointwise and in distribution, in each view (eye-in-hand, third-person), and
// whether the representation keeps the information in the chunk (injectivity.hpp).
//
//   representation : actions, observation (pointwise); the input and the target of its flow:
//                    the rectified flow of eq. (5), or a flow of its own (a plug-in's),
//                    pointwise and in distribution.
//   flow target    : its input and target, pointwise and in distribution.
// And what the paper says each built-in should give (App. A), to assert and to report against.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "handcentric/core/flow_target.hpp"
#include "handcentric/core/representation.hpp"
#include "handcentric/props/checks/check.hpp"
#include "handcentric/props/checks/distribution.hpp"
#include "handcentric/props/checks/injectivity.hpp"
#include "handcentric/props/checks/preflight.hpp"
#include "handcentric/props/named_output.hpp"
#include "handcentric/props/verdict.hpp"

namespace handcentric::props {

struct ClassifierOptions {
  /// cases, seed, tolerance and scene sizes; the world points are set per view.
  CheckOptions check = eye_in_hand_options();
  DistributionOptions distribution = {};
  std::vector<Group> groups = all_groups();
  std::vector<View> views = {View::eye_in_hand, View::third_person};
  bool observation = true;  ///< check the observation (off for a plug-in that sends none)
  bool flow = true;         ///< check the flow of a representation
  bool in_distribution = true;
  /// A whole policy's in-distribution verdict from its pointwise "yes" when the preflight found
  /// it a function of its inputs (policy_audit.hpp, Method::from_pointwise); false runs the
  /// in-distribution tests on every cell.
  bool law_from_pointwise = true;
  bool injectivity = true;      ///< run check_injectivity on a representation
  int injectivity_cases = 200;  ///< chunk pairs it tries (on third-person scenes)
  /// When a cell fails at a tolerance below a lower precision's rounding, re-check it there
  /// (float32, then bfloat16) and say in the verdict's note if it would pass (with_precision_note).
  bool precision_note = true;
  /// The advice that ends that note for a precision's name, in the caller's words (the Python
  /// module says precision="float32").
  std::function<std::string(const std::string& precision)> precision_advice =
      [](const std::string& precision) { return "rerun with --precision " + precision; };
  /// Run the preflight of a whole policy (preflight.hpp) before its verdicts: a policy that is
  /// not a function of its inputs gets no pointwise verdict or none at all.
  bool preflight = true;
  /// The fixes the preflight's messages name, in the caller's words.
  PreflightSpelling preflight_spelling;
  /// Called after each verdict (and the injectivity check) with how many are done of how many
  /// the classification runs: a progress line. May throw to stop the classification.
  std::function<void(int done, int total)> progress;
};

struct Classification {
  std::string name;
  std::vector<Verdict> verdicts;           ///< one per (view, component, mode, group) checked
  std::optional<Injectivity> injectivity;  ///< representations only
  std::optional<Preflight> preflight;      ///< whole policies, when ClassifierOptions::preflight
  /// The policy output these verdicts are about, when it names several (named_output.hpp).
  std::optional<NamedOutput> output;
};

/// `flow`: the flow to audit; null = the rectified flow of `representation` (eq. 5).
Classification classify_representation(std::shared_ptr<const Representation> representation,
                                       const ClassifierOptions& options = {},
                                       std::shared_ptr<const FlowTarget> flow = nullptr);

Classification classify_flow_target(std::shared_ptr<const FlowTarget> target,
                                    const ClassifierOptions& options = {});

/// A failure at a tolerance tighter than a lower precision's rounding that passes at that
/// rounding is worth a sentence: the map is probably right and computed in that precision. If
/// options ask for it and `verdict` failed below kFloat32RelativeTolerance, reruns `recheck`
/// there (no shrinking) and sets the verdict's note when it holds; when it does not, and the
/// witness's error is within reach of bfloat16 rounding (at most 8 sqrt(2^-8) (1 + L)), the
/// same at bfloat16's floor and unit (tolerance.hpp).
Verdict with_precision_note(Verdict verdict, const ClassifierOptions& options,
                            const std::function<Verdict(const CheckOptions&)>& recheck);

/// The cases of a failed verdict for another check (CheckOptions::extra_cases): its witness, then
/// the failing case as first drawn when that is another one (the witness is shrunk to barely
/// fail, where a law's difference can hide in its spread; the case drawn is a typical failure).
/// None when it held.
std::vector<std::pair<Scene, RigidTransform>> witness_cases(const Verdict& verdict);

/// `check` with the scenes of `view` (its world-point counts), everything else kept; a fixed
/// count of world points (min = max >= 1) in `check` is kept for the third-person view.
CheckOptions with_view(CheckOptions check, View view);

/// The groups whose verdict for (component, mode, view) held, in all_groups() order.
std::vector<Group> invariant_groups(const Classification& classification, Component component,
                                    Mode mode, View view = View::eye_in_hand);

/// The verdict for (component, mode, group, view), or null when it was not checked.
const Verdict* find_verdict(const Classification& classification, Component component, Mode mode,
                            Group group, View view = View::eye_in_hand);

/// What we assert for a built-in, and on what authority.
struct Expectation {
  std::vector<Group> groups;  ///< the groups that leave (component, mode) invariant
  std::string basis;          ///< "paper, App. A" or why we expect it where the paper is silent
};

/// The expectation for a built-in's (component, mode) in `view`; empty for a name or component
/// the paper and this library are silent on.
///   eye_in_hand (the paper's setting, App. A): absolute none; relative, relative_diff: actions
///     and flow target under translation only, observation and flow input under none;
///     hand_centric everything under all five; actionflow pointwise none, flow target in
///     distribution under rotation and c8 only.
///   third_person: the same cells, but on this library's authority, not the paper's (Theorem 1
///     assumes eye-in-hand views): world points are copied raw by absolute, relative,
///     relative_diff and ActionFlow's input (never invariant), and taken into the hand frame,
///     T_0^{-1} q, by hand_centric (invariant under all five).
std::optional<Expectation> paper_expectation(const std::string& name, Component component,
                                             Mode mode, View view = View::eye_in_hand);

/// The cells of `classification` that differ from paper_expectation, one line each.
std::vector<std::string> mismatches_with_paper(const Classification& classification);

}  // namespace handcentric::props
