// Item 3 of the claims report: what the certificates find in the paper itself. Each finding is
// a certificate (identity or exact counterexample); whether it confirms or corrects the printed
// text is what it finds, not what is assumed here.
#include "handcentric/proofs/claims.hpp"
#include "handcentric/proofs/flows.hpp"
#include "handcentric/proofs/rational_rotation.hpp"

namespace handcentric::proofs {
namespace {

constexpr ClaimSection kSection = ClaimSection::paper_findings;

const ExactPose& hand_k(const Instance& x) {
  return x.scene.chunk.front();
}

// ActionFlow's target on the moved scene, exactly: (R~ R_k)^T (R~ p_k + p~ - eps).
GiNaC::matrix moved_actionflow(const Instance& x) {
  return flows::actionflow_translation(x.g * x.scene, x.eps);
}

Instance actionflow_witness(const ExactPose& g, const ExactPose& world_T_handk,
                            const GiNaC::matrix& eps) {
  Instance x;
  x.g = g;
  x.scene.history = {ExactPose{}};
  x.scene.chunk = {world_T_handk};
  x.eps = eps;
  return x;
}

std::string actionflow_inputs(const Instance& x) {
  return "T~ = " + pose_text(x.g) + ", T_k = " + pose_text(hand_k(x)) +
         ", eps = " + column_text(x.eps);
}

// eq. (28) with the path x_t of eq. (27): R_k^T (p_k - x_t) / (1 - t), x_t = t v + (1 - t) eps.
GiNaC::matrix eq28_with_path(const Instance& x, const GiNaC::matrix& v) {
  const ExactPose& world_T_handk = hand_k(x);
  const GiNaC::matrix x_t = v.mul_scalar(x.t).add(x.eps.mul_scalar(1 - x.t));
  return world_T_handk.R.transpose().mul(world_T_handk.p.sub(x_t)).mul_scalar(1 / (1 - x.t));
}

std::vector<Claim> eq27_claims() {
  Side eq29 = [](const Instance& x) { return flows::actionflow_translation(x.scene, x.eps); };
  Side with_p = [](const Instance& x) { return eq28_with_path(x, hand_k(x).p); };
  Side with_r_as_printed = [](const Instance& x) {
    return eq28_with_path(x, exact_rotation_vector(hand_k(x).R));
  };
  Instance w = actionflow_witness(ExactPose{}, ExactPose{quarter_turn(2, 1), column(1, 0, 0)},
                                  column(0, 0, 0));
  w.t = GiNaC::numeric(1, 2);
  return {
      identity_claim(
          "A.4 eqs. (27)-(29), path on p",
          "With the path x_t = t p_k + (1 - t) eps, eq. (28) R_k^T (p_k - x_t) / (1 - t) "
          "equals eq. (29) R_k^T (p_k - eps).",
          kSection, with_p, eq29, Group::rigid_motions,
          "For every t != 1 (the factor (1 - t) cancels)."),
      counterexample_claim(
          "A.4 eq. (27) as printed",
          "With eq. (27) as printed, x_t = t r_k + (1 - t) eps (the rotation vector), "
          "eq. (28) does not give eq. (29): the printed r is a typo for p.",
          kSection, with_r_as_printed, eq29, w,
          WitnessText(actionflow_inputs(w) + ", t = 1/2, r_k = r(R_k) = (0, 0, pi/2)",
                      "eq. (28) on the printed path", "eq. (29)"),
          "Found: the paper prints 't W r_Rk' in eq. (27) where W p_Rk is meant; "
          "eq. (29) follows only from the path on p (previous claim)."),
  };
}

std::vector<Claim> eq30_claims() {
  Side first_printed = [](const Instance& x) {  // (R~ R_k)^T (R~ p_k + p~ - eps)
    const ExactPose& Tk = hand_k(x);
    return x.g.R.mul(Tk.R).transpose().mul(x.g.R.mul(Tk.p).add(x.g.p).sub(x.eps));
  };
  // The middle expression R_k^T (p_k + R~ p~ - R~^T eps), term by term against the exact one.
  Side exact_pk_and_eps_terms = [](const Instance& x) {
    const GiNaC::matrix moved_Rk_T = x.g.R.mul(hand_k(x).R).transpose();
    return moved_Rk_T.mul(x.g.R.mul(hand_k(x).p).sub(x.eps));
  };
  Side printed_pk_and_eps_terms = [](const Instance& x) {
    return hand_k(x).R.transpose().mul(hand_k(x).p.sub(x.g.R.transpose().mul(x.eps)));
  };
  Side exact_ptilde_term = [](const Instance& x) {
    return x.g.R.mul(hand_k(x).R).transpose().mul(x.g.p);
  };
  Side printed_ptilde_term = [](const Instance& x) {
    return hand_k(x).R.transpose().mul(x.g.R.mul(x.g.p));
  };
  Side corrected_middle = [](const Instance& x) {
    const GiNaC::matrix Rg_T = x.g.R.transpose();
    return hand_k(x).R.transpose().mul(hand_k(x).p.add(Rg_T.mul(x.g.p)).sub(Rg_T.mul(x.eps)));
  };
  const Instance w = actionflow_witness(ExactPose{rational_rotation(2, 0, 0, 1), column(1, 0, 0)},
                                        ExactPose{}, column(0, 0, 0));
  return {
      identity_claim(
          "A.4 eq. (30), first expression",
          "The first expression of eq. (30), (R~ R_k)^T (R~ p_k + p~ - eps), is ActionFlow's "
          "flow on the moved scene.",
          kSection, moved_actionflow, first_printed, Group::rigid_motions),
      identity_claim(
          "A.4 eq. (30), middle: p_k and eps terms",
          "In eq. (30)'s middle expression R_k^T (p_k + R~ p~ - R~^T eps), the p_k and eps "
          "terms are right: (R~ R_k)^T (R~ p_k - eps) = R_k^T (p_k - R~^T eps).",
          kSection, exact_pk_and_eps_terms, printed_pk_and_eps_terms, Group::rigid_motions),
      counterexample_claim(
          "A.4 eq. (30), middle: p~ term as printed",
          "In eq. (30)'s middle expression the p~ term is wrong as printed: "
          "(R~ R_k)^T p~ = R_k^T R~^T p~, not R_k^T R~ p~.",
          kSection, exact_ptilde_term, printed_ptilde_term, w,
          WitnessText(actionflow_inputs(w), "exact (R~ R_k)^T p~", "printed R_k^T R~ p~"),
          "Found: the paper prints R~ p~ where R~^T p~ is meant. The conclusion of "
          "eq. (30) (not invariant) still holds: item 2."),
      identity_claim(
          "A.4 eq. (30), middle corrected",
          "With R~^T p~, the middle expression R_k^T (p_k + R~^T p~ - R~^T eps) equals the "
          "moved flow exactly.",
          kSection, moved_actionflow, corrected_middle, Group::rigid_motions),
  };
}

// Sec. 5 says ActionFlow's flow is rotation-invariant, App. A.4 that it depends on rotations.
std::vector<Claim> actionflow_distribution_claims() {
  // Coupling eps' = R~ eps: target(T~ scene, R~ eps) = target(scene, eps), and |R~ eps| = |eps|.
  Side moved_with_rotated_noise = [](const Instance& x) {
    const GiNaC::matrix rotated_eps = x.g.R.mul(x.eps);
    const GiNaC::ex norm2 = rotated_eps.transpose().mul(rotated_eps)(0, 0);
    return stack(flows::actionflow_translation(x.g * x.scene, rotated_eps), GiNaC::matrix{{norm2}});
  };
  Side unmoved_with_noise = [](const Instance& x) {
    const GiNaC::ex norm2 = x.eps.transpose().mul(x.eps)(0, 0);
    return stack(flows::actionflow_translation(x.scene, x.eps), GiNaC::matrix{{norm2}});
  };
  // The target is affine in eps and E[eps] = 0, so its mean is the target at eps = 0.
  Side moved_mean = [](const Instance& x) {
    return flows::actionflow_translation(x.g * x.scene, column(0, 0, 0));
  };
  Side unmoved_mean = [](const Instance& x) {
    return flows::actionflow_translation(x.scene, column(0, 0, 0));
  };
  const Instance w =
      actionflow_witness(translation_pose(column(1, 0, 0)), ExactPose{}, column(0, 0, 0));
  return {
      identity_claim(
          "Sec. 5 vs A.4, rotations in distribution",
          "ActionFlow's translation flow is rotation-invariant in distribution: under a "
          "rotation R~, the target at (R~ scene, R~ eps) equals the target at (scene, eps) "
          "and |R~ eps| = |eps|, so with eps ~ N(0, I) the target's law is unchanged.",
          kSection, moved_with_rotated_noise, unmoved_with_noise, Group::rotations,
          "Both statements of the paper hold, in different senses: Sec. 5 (rotation-invariant) "
          "in distribution, App. A.4 (depends on rotations) pointwise for a fixed eps "
          "(item 2). The sampled counterpart is `handcentric audit --json`, mode "
          "\"distribution\", for the actionflow target."),
      counterexample_claim(
          "Sec. 5 vs A.4, translations in distribution",
          "ActionFlow's translation flow is not translation-invariant even in "
          "distribution: its mean R_k^T p_k (the target at eps = 0) moves.",
          kSection, moved_mean, unmoved_mean, w,
          WitnessText(actionflow_inputs(w), "mean on T~ scene", "mean on scene"),
          "The target is affine in eps and E[eps] = 0, so its mean is the target at "
          "eps = 0; different means, different laws. Sec. 5 says so too."),
  };
}

}  // namespace

std::vector<Claim> paper_finding_claims() {
  std::vector<Claim> claims;
  claims.push_back(identity_claim(
      "Sec. 2.1 vs A.2 eq. (14)",
      "Sec. 2.1's relative rotation r(R_0^T R_k) is invariant under global rotations "
      "((R~ R_0)^T (R~ R_k) = R_0^T R_k), unlike App. A.2 eq. (14)'s r(R_k) - r(R_0).",
      kSection, moved([](const ExactScene& s, const GiNaC::matrix&, const GiNaC::ex&) {
        return flows::relative_rotation_matrix(s);
      }),
      unmoved([](const ExactScene& s, const GiNaC::matrix&, const GiNaC::ex&) {
        return flows::relative_rotation_matrix(s);
      }),
      Group::rotations,
      "Found: the paper defines 'relative' twice, and only eq. (14)'s version is not "
      "rotation-invariant (counterexample 'A.2 eq. (18)', item 2). Which one Table 1's 'Relative' "
      "uses is unknown: the paper does not say. core has both (`relative`, `relative_diff`)."));
  for (Claim& claim : eq27_claims()) claims.push_back(std::move(claim));
  for (Claim& claim : eq30_claims()) claims.push_back(std::move(claim));
  for (Claim& claim : actionflow_distribution_claims()) claims.push_back(std::move(claim));
  return claims;
}

}  // namespace handcentric::proofs
