// `handcentric report` (and plain `handcentric`): the main report, and its first section: the
// audit summary of the built-ins (`handcentric audit` without witnesses), one compact table per
// representation, compared cell by cell with what App. A of the paper says.
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/props/audit.hpp"

namespace handcentric::apps {
namespace {

int run_audit_section(const ReportOptions& options, std::ostream& out) {
  props::AuditOptions audit;
  audit.cases = options.cases;
  audit.seed = options.seed;
  const props::ClassifierOptions used = props::classifier_options(audit);  // validates --cases
  out << "1. Audit of the built-in representations (handcentric audit; witnesses there)\n"
      << "   " << audit.cases << " cases per pointwise cell, " << used.distribution.cases
      << " per in-distribution cell, seed " << audit.seed
      << "; 'yes' = invariant, the number = largest error seen\n\n";
  const std::vector<props::Classification> results = props::audit_builtins({}, audit);
  props::print_audit(out, results, audit, /*witnesses=*/false);
  std::vector<std::string> mismatches;
  for (const auto& classification : results) {
    for (auto& line : props::mismatches_with_paper(classification))
      mismatches.push_back(std::move(line));
  }
  if (mismatches.empty()) {
    out << "Every cell matches App. A of the paper in the eye-in-hand view: absolute - no symmetry "
           "(eqs. 11, "
           "13); relative and relative_diff - translation only (eq. 16); hand_centric - all of "
           "SE(3) (eqs. 9, "
           "23, 26); ActionFlow - pointwise none, in distribution rotations only (eq. 29). The "
           "third-person "
           "cells match the same pattern, on this library's rule for world points (copied raw by "
           "absolute, "
           "relative, relative_diff and ActionFlow; taken into the hand frame by hand_centric).\n";
    return 0;
  }
  out << mismatches.size() << " cell(s) differ from the paper:\n";
  for (const auto& line : mismatches) out << "  " << line << "\n";
  return 1;
}

void add_report_command(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<ReportOptions>();
  CLI::App* cmd = app.add_subcommand("report", "the main report (what plain `handcentric` runs)");
  cmd->add_option("--cases", options->cases, "cases per pointwise cell of the audit section")
      ->capture_default_str();
  cmd->add_option("--seed", options->seed, "seed of the audit section")->capture_default_str();
  cmd->callback([options, &exit_code] { exit_code = run_main_report(std::cout, *options); });
}

const CommandRegistration report_command("report", add_report_command);
const ReportSection audit_section(10, "audit", [](std::ostream& out, const ReportOptions& options) {
  return run_audit_section(options, out);
});

}  // namespace
}  // namespace handcentric::apps
