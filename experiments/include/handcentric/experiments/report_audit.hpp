#pragma once
// The main report's audit: every built-in representation and ActionFlow's target under every
// group, both views, compared cell by cell with what App. A of the paper says
// (props::mismatches_with_paper). The terminal report prints it as tables, the report page as
// verdict grids (report_page.hpp); both run it here, on the same options.
#include <cstdint>
#include <string>
#include <vector>

#include "handcentric/props/audit.hpp"

namespace handcentric::experiments {

struct ReportAudit {
  props::AuditOptions options;                 ///< what ran: all groups and views
  props::ClassifierOptions classifier;         ///< the cases per cell that ran
  std::vector<props::Classification> results;  ///< one per built-in, then ActionFlow's target
  std::vector<std::string> mismatches;         ///< the cells that differ from App. A, one line each
};

/// The audit's options at `cases` and `seed`, checked (InvalidArgument naming --cases, the value
/// and its bound), before anything runs.
props::AuditOptions report_audit_options(long long cases, std::uint64_t seed);

/// Runs the audit of report_audit_options(cases, seed).
ReportAudit run_report_audit(long long cases, std::uint64_t seed);

/// What App. A says of the built-ins, after "Every cell matches App. A of the paper" when every
/// cell does: the eye-in-hand pattern and this library's rule for world points (one paragraph).
inline constexpr const char* kPaperPattern =
    " in the eye-in-hand view: absolute - no symmetry (eqs. 11, 13); relative and relative_diff "
    "- translation only (eq. 16); hand_centric - all of SE(3) (eqs. 9, 23, 26); ActionFlow - "
    "pointwise none, in distribution rotations only (eq. 29). The third-person cells match the "
    "same pattern, on this library's rule for world points (copied raw by absolute, relative, "
    "relative_diff and ActionFlow; taken into the hand frame by hand_centric).";

}  // namespace handcentric::experiments
