#include "handcentric/proofs/claims.hpp"

namespace handcentric::proofs {

std::vector<Claim> paper_claims() {
  std::vector<Claim> all = identity_claims();
  for (Claim& claim : counterexample_claims()) all.push_back(std::move(claim));
  for (Claim& claim : paper_finding_claims()) all.push_back(std::move(claim));
  return all;
}

std::vector<ClaimOutcome> certify_all(const std::vector<Claim>& claims) {
  std::vector<ClaimOutcome> outcomes;
  outcomes.reserve(claims.size());
  for (const Claim& claim : claims) outcomes.push_back(certify(claim));
  return outcomes;
}

int count_verified(const std::vector<ClaimOutcome>& outcomes) {
  int verified = 0;
  for (const ClaimOutcome& outcome : outcomes) verified += outcome.result.verified ? 1 : 0;
  return verified;
}

}  // namespace handcentric::proofs
