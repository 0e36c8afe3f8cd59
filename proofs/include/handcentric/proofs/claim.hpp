#pragma once
// A claim of the paper, tied to its equation number, with the certificate that checks it.
//
//   id        : where it is in the paper, e.g. "A.3 eq. (23)"
//   statement : what is claimed, in words (for a counterexample: what does NOT hold)
//   kind      : identity (holds for every input) or counterexample (fails on one exact input)
//   note      : how to read the certificate, and what it finds in the paper (may be empty)
//
// identity_claim / counterexample_claim build the certificate from two Sides (certificate.hpp).
#include <functional>
#include <string>

#include "handcentric/proofs/certificate.hpp"

namespace handcentric::proofs {

enum class ClaimKind { identity, counterexample };

/// "identity" or "counterexample".
std::string kind_name(ClaimKind kind);

/// Which part of the claims report a claim belongs to.
enum class ClaimSection {
  identities,       ///< what the paper proves, proved symbolically
  counterexamples,  ///< what the paper says does not hold, shown by exact counterexamples
  paper_findings,   ///< what the certificates find in the paper itself
};

/// The section's title in the report.
std::string section_title(ClaimSection section);

struct Claim {
  std::string id;
  std::string statement;
  ClaimKind kind = ClaimKind::identity;
  ClaimSection section = ClaimSection::identities;
  std::string note;
  std::function<CertificateResult()> certify;  ///< the certificate check
  // What the check compares, kept so that tests can plant a fault in a claim:
  Side lhs;
  Side rhs;
  Group group = Group::rigid_motions;  ///< identity: the generic instance's group
  Instance witness;                    ///< counterexample: the exact witness
  WitnessText inputs;                  ///< counterexample: the witness in words
};

/// A claim that lhs = rhs for every instance of `group` (symbols everywhere).
Claim identity_claim(std::string id, std::string statement, ClaimSection section, Side lhs,
                     Side rhs, Group group, std::string note = "");

/// A claim that lhs != rhs at the exact `witness`, described by `inputs` in the report.
Claim counterexample_claim(std::string id, std::string statement, ClaimSection section, Side lhs,
                           Side rhs, Instance witness, WitnessText inputs, std::string note = "");

/// A claim and what its certificate found.
struct ClaimOutcome {
  std::string id;
  std::string statement;
  ClaimKind kind = ClaimKind::identity;
  ClaimSection section = ClaimSection::identities;
  std::string note;
  CertificateResult result;
};

/// Runs the certificate. A certificate that throws is reported as not verified, with the error.
ClaimOutcome certify(const Claim& claim);

}  // namespace handcentric::proofs
