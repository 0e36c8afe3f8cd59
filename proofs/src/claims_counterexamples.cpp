// Item 2 of the claims report: what the paper says does NOT hold, shown by one exact
// counterexample each. Witnesses use rational rotations (3-4-5 rotations from integer
// quaternions, quarter turns), rational translations and rational noise, so both sides are
// evaluated with no rounding.
#include "handcentric/proofs/claims.hpp"
#include "handcentric/proofs/flows.hpp"
#include "handcentric/proofs/rational_rotation.hpp"

namespace handcentric::proofs {
namespace {

constexpr ClaimSection kCounterexamples = ClaimSection::counterexamples;

// The 3-4-5 rotation about z: cos = 3/5, sin = 4/5 (q = (2, 0, 0, 1)).
GiNaC::matrix rotation_345() {
  return rational_rotation(2, 0, 0, 1);
}

// A witness with T_0, T_k and eps, and its description.
struct Witness {
  Instance instance;
  std::string inputs;
};

Witness witness(const ExactPose& g, const ExactPose& world_T_hand0, const ExactPose& world_T_handk,
                const GiNaC::matrix& eps) {
  Witness w;
  w.instance.g = g;
  w.instance.scene.history = {world_T_hand0};
  w.instance.scene.chunk = {world_T_handk};
  w.instance.eps = eps;
  w.inputs = "T~ = " + pose_text(g) + ", T_0 = " + pose_text(world_T_hand0) +
             ", T_k = " + pose_text(world_T_handk) + ", eps = " + column_text(eps);
  return w;
}

Claim invariance_counterexample(std::string id, std::string statement, const Flow& flow,
                                const Witness& w, std::string note = "") {
  return counterexample_claim(std::move(id), std::move(statement), kCounterexamples, moved(flow),
                              unmoved(flow), w.instance,
                              WitnessText(w.inputs, "f(T~ scene)", "f(scene)"), std::move(note));
}

// eq. (13): certified on the matrices R~ R_k != R_k, both of angle below pi (tr R > -1).
Claim eq13_claim() {
  const Witness w =
      witness(rotation_pose(rotation_345()), ExactPose{}, ExactPose{}, column(0, 0, 0));
  Claim claim = invariance_counterexample(
      "A.1 eq. (13)",
      "The absolute rotation flow r(R_k) - eps is not invariant under global rotations.",
      ignoring_noise(flows::absolute_rotation_matrix), w,
      "A rotation vector is transcendental in general, so this is certified on the exact matrices: "
      "R~ R_k != R_k, and both have angle below pi (trace > -1, checked exactly). r is injective "
      "on rotations of angle below pi, so r(R~ R_k) - eps != r(R_k) - eps.");
  const auto matrices_differ = claim.certify;
  claim.certify = [matrices_differ, w] {
    CertificateResult result = matrices_differ();
    const GiNaC::matrix moved_R = w.instance.g.R.mul(w.instance.scene.chunk.front().R);
    const GiNaC::matrix& R = w.instance.scene.chunk.front().R;
    const bool below_pi = has_angle_below_pi(moved_R) && has_angle_below_pi(R);
    if (!below_pi) {
      result.verified = false;
      result.detail += "; but an angle is pi, where r is not injective";
    }
    return result;
  };
  return claim;
}

// Lemma 2 needs eye-in-hand points: a world point given to the policy as is moves with T~.
Claim third_person_claim() {
  Witness w = witness(translation_pose(column(1, 0, 0)), ExactPose{}, ExactPose{}, column(0, 0, 0));
  w.instance.scene.history.push_back(ExactPose{});  // T_{-h} = I
  w.instance.scene.world_points = {column(0, 0, 0)};
  w.inputs += ", T_{-h} = [I | (0, 0, 0)], world point x = (0, 0, 0)";
  return invariance_counterexample(
      "Sec. 3.2 Lemma 2, third-person",
      "Without the eye-in-hand assumption Lemma 2's input is not invariant: a world-frame point "
      "passed to the policy as is moves with a global translation.",
      ignoring_noise(flows::inner_policy_input_third_person), w,
      "Why Theorem 1 assumes eye-in-hand observations (Sec. 3.2, Sec. 6).");
}

}  // namespace

std::vector<Claim> counterexample_claims() {
  const GiNaC::matrix zero = column(0, 0, 0);
  const ExactPose rotate_345 = rotation_pose(rotation_345());
  std::vector<Claim> claims;
  claims.push_back(invariance_counterexample(
      "A.1 eq. (11), translations",
      "The absolute translation flow p_k - eps is not invariant under global translations.",
      with_noise(flows::absolute_translation),
      witness(translation_pose(column(0, 1, 0)), ExactPose{}, translation_pose(column(1, 0, 0)),
              zero)));
  claims.push_back(invariance_counterexample(
      "A.1 eq. (11), rotations",
      "The absolute translation flow p_k - eps is not invariant under global rotations.",
      with_noise(flows::absolute_translation),
      witness(rotate_345, ExactPose{}, translation_pose(column(1, 0, 0)), zero)));
  claims.push_back(eq13_claim());
  claims.push_back(invariance_counterexample(
      "A.2 eq. (16), rotations",
      "The relative translation flow p_k - p_0 - eps is not invariant under global rotations.",
      with_noise(flows::relative_translation),
      witness(rotate_345, ExactPose{}, translation_pose(column(1, 0, 0)), zero)));
  claims.push_back(invariance_counterexample(
      "A.2 eq. (18)",
      "The relative_diff rotation flow r(R_k) - r(R_0) - eps (App. A.2 eq. (14)) is not invariant "
      "under global rotations.",
      with_noise(flows::relative_diff_rotation),
      witness(rotation_pose(quarter_turn(0, 1)), ExactPose{}, rotation_pose(quarter_turn(2, 1)),
              zero),
      "Exact rotation vectors: every rotation involved is a product of quarter turns with angle "
      "pi/2 or 2 pi/3, whose r(.) is exact in Q(sqrt(3), pi)."));
  claims.push_back(invariance_counterexample(
      "A.4 eq. (30), translations",
      "ActionFlow's translation flow R_k^T (p_k - eps) is not invariant under global translations "
      "(pointwise, fixed eps).",
      with_noise(flows::actionflow_translation),
      witness(translation_pose(column(1, 0, 0)), ExactPose{}, ExactPose{}, zero)));
  claims.push_back(invariance_counterexample(
      "A.4 eq. (30), rotations",
      "ActionFlow's translation flow R_k^T (p_k - eps) is not invariant under global rotations "
      "(pointwise, fixed eps).",
      with_noise(flows::actionflow_translation),
      witness(rotate_345, ExactPose{}, ExactPose{}, column(1, 0, 0)),
      "Pointwise: the same eps before and after. In distribution it is rotation-invariant (item "
      "3)."));
  claims.push_back(third_person_claim());
  return claims;
}

}  // namespace handcentric::proofs
