#pragma once
// The certificates on the report page: one row per claim of the paper (its equation number,
// statement, kind, verdict) linking to its line of docs/CLAIMS.md, and that file beside the page
// twice: as CLAIMS.md (what the repository holds: proofs::report_markdown of the same outcomes,
// which a test keeps equal to docs/CLAIMS.md) and as claims.html, its lines numbered, each an
// anchor "L<n>", so a link opens at the claim.
#include <vector>

#include "handcentric/experiments/document.hpp"
#include "handcentric/proofs/claims.hpp"

namespace handcentric::experiments {

struct ClaimsPart {
  Table table;
  std::vector<PageFile> files;  ///< CLAIMS.md and claims.html
  int verified = 0;
};

ClaimsPart claims_part(const std::vector<proofs::ClaimOutcome>& outcomes);

/// The equation (or lemma) a claim's id names: "A.4 eqs. (27)-(29), path on p" -> "(27)-(29)",
/// "Sec. 3.1 Lemma 1, eq. (8)" -> "(8)", "Sec. 3.2 Lemma 2, third-person" -> "Lemma 2"; "-"
/// when it names neither.
std::string equation_of(const std::string& claim_id);

/// The 1-based line of "### <claim id>" in `markdown`; 0 when it is not there.
int claim_line(const std::string& markdown, const std::string& claim_id);

}  // namespace handcentric::experiments
