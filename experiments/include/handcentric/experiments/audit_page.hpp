#pragma once
// The audit on the report page: each classification (a representation, ActionFlow's target or an
// audited policy) as one verdict grid per view, rows the components and modes, columns the
// groups; each cell yes / NO, its largest error and unit, and for in-distribution cells how it was
// decided (exact / test). Each NO cell links to its witness below: the scene, g, both outputs as
// a small table, and the scene from above as an SVG file beside the page.
#include <vector>

#include "handcentric/experiments/document.hpp"
#include "handcentric/props/audit.hpp"

namespace handcentric::experiments {

/// The grids (a level-3 section per classification), the witnesses (a level-3 section per
/// classification with a failing cell, a level-4 section per witness: kept apart so that the
/// grids read one after the other and the witnesses are a click away) and the witness pictures
/// (under "witness/"). Ids start with `prefix` so that two audits can share a page.
struct AuditPart {
  std::vector<Section> grids;
  std::vector<Section> witnesses;
  std::vector<PageFile> files;
};

AuditPart audit_part(const std::vector<props::Classification>& classifications,
                     const props::AuditOptions& options, const std::string& prefix = "audit");

/// What a cell shows as its method: "exact" (exact_gaussian), "partly exact", "test"
/// (energy_test); empty for a pointwise cell.
std::string method_label(const props::Verdict& verdict);

}  // namespace handcentric::experiments
