// Item 1 of the claims report: what the paper proves, proved symbolically. Every identity below
// is checked on a generic instance (generic_instance(): rotations R(q) with q four symbols,
// translations, points, noise and time all symbols), so it holds for every input.
#include "handcentric/proofs/claims.hpp"
#include "handcentric/proofs/flows.hpp"
#include "handcentric/proofs/quaternion_rotation.hpp"

namespace handcentric::proofs {
namespace {

constexpr ClaimSection kIdentities = ClaimSection::identities;

// Lemma 1 / eq. (8): the inner policy's action Ra_k is invariant, so it is one generic pose that
// does not depend on g; the outer action is a_k = T_0 Ra_k (Theorem 1).
Claim lemma1_claim() {
  const ExactPose hand0_T_handk = generic_pose("a");  // Ra_k, shared by both sides
  Side outer_of_moved_scene = [hand0_T_handk](const Instance& x) {
    const ExactPose moved_world_T_hand0 = x.g * x.scene.history.front();
    return (moved_world_T_hand0 * hand0_T_handk).entries();  // a_k(T~ o) = (T~ T_0) Ra_k, eq. (7)
  };
  Side moved_outer_action = [hand0_T_handk](const Instance& x) {
    return (x.g * (x.scene.history.front() * hand0_T_handk)).entries();  // T~ a_k(o)
  };
  return identity_claim(
      "Sec. 3.1 Lemma 1, eq. (8)",
      "If the hand-centric policy is invariant, the outer action a_k = T_0 Ra_k is "
      "SE(3)-equivariant: moving the scene by T~ gives (T~ T_0) Ra_k = T~ a_k.",
      kIdentities, outer_of_moved_scene, moved_outer_action, Group::rigid_motions,
      "Ra_k is a generic pose that does not depend on T~ (the invariance assumed by Lemma 1); "
      "the identity is on all 12 entries of the pose.");
}

// eq. (11) as printed: R~ p_k + p~ - eps = T~ o (p_k - eps) + R~ eps - eps,
// with T~ o v = R~ v + p~.
Claim eq11_printed_claim() {
  Side printed_right = [](const Instance& x) {
    const GiNaC::matrix flow = flows::absolute_translation(x.scene, x.eps);
    return (x.g * flow).add(x.g.R.mul(x.eps)).sub(x.eps);
  };
  return identity_claim(
      "A.1 eq. (11), right-hand side",
      "The moved absolute translation flow equals the printed T~ o (p_k - eps) + R~ eps - eps.",
      kIdentities, moved(with_noise(flows::absolute_translation)), printed_right,
      Group::rigid_motions,
      "T~ o v is read as R~ v + p~ (a point moved by T~). The printed algebra is right; the "
      "non-invariance it shows is certified under item 2.");
}

}  // namespace

std::vector<Claim> identity_claims() {
  std::vector<Claim> claims;
  claims.push_back(identity_claim(
      "Sec. 3.2 eq. (9)",
      "Hand-centric proprioception is SE(3)-invariant: (T~ T_0)^{-1} T~ T_{-h} = T_0^{-1} T_{-h}.",
      kIdentities, moved(ignoring_noise(flows::hand_centric_proprioception)),
      unmoved(ignoring_noise(flows::hand_centric_proprioception)), Group::rigid_motions,
      "All 12 entries of the pose, with T~, T_0 and T_{-h} generic."));
  claims.push_back(identity_claim(
      "A.3 eq. (23)",
      "The hand-centric translation flow R_0^T (p_k - p_0) - eps is SE(3)-invariant.", kIdentities,
      moved(with_noise(flows::hand_centric_translation)),
      unmoved(with_noise(flows::hand_centric_translation)), Group::rigid_motions));
  claims.push_back(identity_claim(
      "A.3 eq. (26)",
      "The hand-centric rotation flow r(R_0^T R_k) - eps is SE(3)-invariant, because "
      "(R~ R_0)^T (R~ R_k) = R_0^T R_k.",
      kIdentities, moved(ignoring_noise(flows::hand_centric_rotation_matrix)),
      unmoved(ignoring_noise(flows::hand_centric_rotation_matrix)), Group::rigid_motions,
      "Certified on the matrix R_0^T R_k; r(.) is a function of the matrix, so r(matrix) - eps "
      "is unchanged too."));
  claims.push_back(identity_claim(
      "A.2 eq. (16), translations",
      "The relative translation flow p_k - p_0 - eps is invariant under global translations.",
      kIdentities, moved(with_noise(flows::relative_translation)),
      unmoved(with_noise(flows::relative_translation)), Group::translations));
  claims.push_back(lemma1_claim());
  claims.push_back(identity_claim(
      "Sec. 3.2 Lemma 2 with eq. (9)",
      "With eye-in-hand points, the hand-centric policy's input [T_0^{-1} T_{-h}, points] is "
      "SE(3)-invariant, so the policy's output (a function of it) is invariant.",
      kIdentities, moved(ignoring_noise(flows::inner_policy_input)),
      unmoved(ignoring_noise(flows::inner_policy_input)), Group::rigid_motions,
      "Eye-in-hand points are expressed in the hand frame and do not move with T~ (Sec. 3.2); "
      "that this assumption is needed is certified under item 2."));
  claims.push_back(eq11_printed_claim());
  return claims;
}

}  // namespace handcentric::proofs
