#include "handcentric/proofs/claim.hpp"

#include <exception>

namespace handcentric::proofs {

std::string kind_name(ClaimKind kind) {
  return kind == ClaimKind::identity ? "identity" : "counterexample";
}

std::string section_title(ClaimSection section) {
  switch (section) {
    case ClaimSection::identities:
      return "Identities, proved symbolically";
    case ClaimSection::counterexamples:
      return "Non-invariance, proved by exact counterexamples";
    case ClaimSection::paper_findings:
      return "What the certificates find in the paper itself";
  }
  return "?";
}

Claim identity_claim(std::string id, std::string statement, ClaimSection section, Side lhs,
                     Side rhs, Group group, std::string note) {
  Claim claim{std::move(id),
              std::move(statement),
              ClaimKind::identity,
              section,
              std::move(note),
              {},
              std::move(lhs),
              std::move(rhs),
              group,
              {},
              WitnessText{}};
  claim.certify = [lhs = claim.lhs, rhs = claim.rhs, group] {
    return certify_identity(lhs, rhs, generic_instance(group));
  };
  return claim;
}

Claim counterexample_claim(std::string id, std::string statement, ClaimSection section, Side lhs,
                           Side rhs, Instance witness, WitnessText inputs, std::string note) {
  Claim claim{std::move(id),
              std::move(statement),
              ClaimKind::counterexample,
              section,
              std::move(note),
              {},
              std::move(lhs),
              std::move(rhs),
              Group::rigid_motions,
              std::move(witness),
              std::move(inputs)};
  claim.certify = [lhs = claim.lhs, rhs = claim.rhs, witness = claim.witness,
                   inputs = claim.inputs] {
    return certify_counterexample(lhs, rhs, witness, inputs);
  };
  return claim;
}

ClaimOutcome certify(const Claim& claim) {
  ClaimOutcome outcome{claim.id, claim.statement, claim.kind, claim.section, claim.note, {}};
  try {
    outcome.result = claim.certify();
  } catch (const std::exception& e) {
    outcome.result = {false, "", std::string("the certificate threw: ") + e.what()};
  }
  return outcome;
}

}  // namespace handcentric::proofs
