#pragma once
// The audit behind `handcentric audit` and the main report: classify representations (the
// built-ins, ActionFlow's target, or a plug-in), then render one table per representation (a
// row per component and mode, a column per group, a mark and the largest error, failing cells'
// witnesses below) or the JSON document of docs/AUDIT.md.
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "handcentric/props/classifier.hpp"

namespace handcentric::props {

struct AuditOptions {
  std::vector<Group> groups = all_groups();
  int cases = kDefaultCases;       ///< pointwise cases per cell
  std::uint64_t seed = 1;
};

/// The names `--repr` accepts: the four built-ins, then "actionflow".
std::vector<std::string> auditable_names();

/// Classifier options for an audit: eye-in-hand scenes; pointwise cells run options.cases
/// cases, distribution cells max(10, ceil(cases / 100)) (each with 32 noise draws and a
/// permutation test).
ClassifierOptions classifier_options(const AuditOptions& options);

/// Audits the named built-ins (empty = all of auditable_names()). Throws InvalidArgument
/// naming an unknown name and the valid ones.
std::vector<Classification> audit_builtins(const std::vector<std::string>& names, const AuditOptions& options);

/// Human output: one table per classification, witnesses of failing cells below it.
/// `witnesses` = false prints the tables only (the main report).
void print_audit(std::ostream& out, const std::vector<Classification>& classifications,
                 const AuditOptions& options, bool witnesses = true);

/// {"representations": [{"name": ..., "checks": [{"component", "group", "mode", "invariant",
/// "max_error", "cases", "seed", "witness"}]}]} (docs/AUDIT.md).
std::string audit_json(const std::vector<Classification>& classifications);

}  // namespace handcentric::props
