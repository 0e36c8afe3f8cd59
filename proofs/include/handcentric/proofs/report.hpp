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

/// A report file that cannot be written: names the path and the reason.
class ReportFileError : public Error {
 public:
  using Error::Error;
};

/// "N/N certificates verified" and one line per claim.
std::string summary_text(const std::vector<ClaimOutcome>& outcomes);

/// Every claim: id, statement, kind, verdict, and for a counterexample its exact witness.
std::string report_text(const std::vector<ClaimOutcome>& outcomes);

/// The JSON document described above, pretty-printed with 2 spaces.
std::string report_json(const std::vector<ClaimOutcome>& outcomes);

/// The markdown claims report (docs/CLAIMS.md).
std::string report_markdown(const std::vector<ClaimOutcome>& outcomes);

/// Writes `contents` to `path` atomically (a temporary file beside it, then rename). Throws
/// ReportFileError naming the path when it cannot be written.
void write_file_atomically(const std::string& path, const std::string& contents);

}  // namespace handcentric::proofs
