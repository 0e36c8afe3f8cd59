#pragma once
// What `handcentric audit` prints above its tables: the settings the verdicts were reached with
// and how to read one, in the command line's words (docs/AUDIT.md has the rules in full).
#include <ostream>

#include "handcentric/props/audit.hpp"

namespace handcentric::props {

/// The header: the cases per pointwise and per in-distribution cell, the seed, the tolerance
/// REL (1 + L) and where REL comes from (--tolerance, or the rounding of a --precision other
/// than float64), the workspace and recorded observations when set; then what 'yes' and the
/// number mean, for whole policies (`policies`: equivariance, eq. 4) or for representations
/// (invariance). Ends with a blank line.
void print_audit_header(std::ostream& out, const AuditOptions& audit, bool policies);

}  // namespace handcentric::props
