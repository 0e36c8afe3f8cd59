#pragma once
// What a cell's evaluation leaves on disk and what Table 1 is built from. One evaluation file
// is exactly `handcentric eval --json` output, so a plan's shell commands and the in-process
// runner write the same files.
#include <optional>
#include <string>
#include <vector>

#include "handcentric/experiments/cell.hpp"
#include "handcentric/experiments/wilson.hpp"
#include "handcentric/sim/rollout.hpp"

namespace handcentric::experiments {

/// `handcentric eval --json`: {"trials", "success", "collision", "timeout" (rates), "clipped",
/// "policy", "dist", "seed"}, one line.
std::string eval_json(const sim::RolloutSummary& summary, const std::string& policy,
                      const std::string& dist, std::uint64_t seed);

/// The counts back from eval_json text. Throws InvalidArgument naming `source` when it is not
/// such an object (a cut or foreign file).
sim::RolloutSummary parse_eval_json(const std::string& text, const std::string& source);

/// One group's verdict of a model's pointwise audit (model_audit.hpp): equivariant or not, and
/// the largest error seen (m and rad, the chunk distance of props/policy_audit.hpp).
struct SymmetryVerdict {
  std::string group;
  bool equivariant = false;
  double max_error = 0.0;
};

/// One row of table1.json.
struct Row {
  std::string method, head;
  int demos = 0, trials = 0, steps = 0;
  std::uint64_t train_seed = 0;
  std::string model;  ///< the cell hash
  std::optional<double> id_success, ood_success, ood_paired_success;
  std::optional<Interval> id_ci, ood_ci;
  /// The model's audit, one verdict per group in the audit's order; empty when not audited.
  std::vector<SymmetryVerdict> symmetry;
};

/// The row of `cell` from whichever of its result files exist under `dir` (missing ones stay
/// empty). Throws InvalidArgument for a damaged result file.
Row collect_row(const Cell& cell, const EvalSettings& eval, const std::string& dir);

/// The eye-in-hand pointwise verdicts of a `handcentric audit --model --json` document. Throws
/// InvalidArgument naming `source` when it is not one.
std::vector<SymmetryVerdict> parse_audit_json(const std::string& text, const std::string& source);

/// {"rows": [...]} with the field names (null for a missing value); "symmetry": the
/// audit's verdicts as {group: {"equivariant", "max_error"}}, null when not audited.
std::string rows_json(const std::vector<Row>& rows);

}  // namespace handcentric::experiments
