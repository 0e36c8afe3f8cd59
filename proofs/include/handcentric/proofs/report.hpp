#pragma once
// The claims report, in three forms, all deterministic (no dates, no timings: docs/CLAIMS.md is
// committed and a test regenerates it):
//
//   text     : what `handcentric prove` prints
//   json     : {"claims": [{"id", "statement", "kind", "verified", "witness", "section", "note",
//               "detail"}], "verified": n, "total": m}; witness is null for an identity
//   markdown : docs/CLAIMS.md, what a reviewer cites
#include <string>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/proofs/claims.hpp"

namespace handcentric::proofs {

/// "N/N certificates verified" and one line per claim.
std::string summary_text(const std::vector<ClaimOutcome>& outcomes);

/// Every claim: id, statement, kind, verdict, and for a counterexample its exact witness.
std::string report_text(const std::vector<ClaimOutcome>& outcomes);

/// The JSON document described above, pretty-printed with 2 spaces.
std::string report_json(const std::vector<ClaimOutcome>& outcomes);

/// The markdown claims report (docs/CLAIMS.md).
std::string report_markdown(const std::vector<ClaimOutcome>& outcomes);

}  // namespace handcentric::proofs
