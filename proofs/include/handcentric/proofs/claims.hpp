#pragma once
// The registry of the paper's claims, in report order: the identities (item 1 of the claims
// report), the counterexamples (item 2), and what the certificates find in the paper (item 3).
// Each list is built in its own file: claims_identities.cpp, claims_counterexamples.cpp,
// claims_paper.cpp.
#include <string>
#include <vector>

#include "handcentric/proofs/claim.hpp"

namespace handcentric::proofs {

/// eqs. (9), (23), (26), (16) under translations, Lemma 1 / eq. (8), Lemma 2 with eq. (9),
/// eq. (11).
std::vector<Claim> identity_claims();

/// eqs. (11), (13), (16) under rotations, (18), (30) pointwise; Lemma 2 without eye-in-hand.
std::vector<Claim> counterexample_claims();

/// Sec. 2.1 vs App. A.2, eq. (27) as printed, eq. (30) term by term, Sec. 5 vs App. A.4.
std::vector<Claim> paper_finding_claims();

/// All of the above, in that order.
std::vector<Claim> paper_claims();

/// Every claim certified.
std::vector<ClaimOutcome> certify_all(const std::vector<Claim>& claims);

/// How many outcomes are verified.
int count_verified(const std::vector<ClaimOutcome>& outcomes);

}  // namespace handcentric::proofs
