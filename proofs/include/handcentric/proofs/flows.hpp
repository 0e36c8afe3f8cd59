#pragma once
// The paper's flows and representation components, written in exact arithmetic on one step k of
// an ExactScene (T_0 = history[0], T_{-h} = history[1], T_k = chunk[0]). Each is the formula of
// the equation it cites, nothing more; the claims (claims.hpp) compare them on moved scenes.
//
// Rotation components are given as the rotation *matrix* that r(.) is applied to (eqs. (12),
// (25), Sec. 2.1): r is a function of the matrix, so an identity on the matrix is an identity on
// r(matrix) - eps; and r is injective on rotations of angle below pi, so two different matrices
// of angle below pi have different r. Only relative_diff (eq. (17)), a difference of two rotation
// vectors, needs r itself: it uses exact_rotation_vector() and so works on exact witnesses only.
#include <ginac/ginac.h>

#include "handcentric/proofs/exact_pose.hpp"

namespace handcentric::proofs::flows {

/// eq. (10): p_k - eps (absolute translation).
GiNaC::matrix absolute_translation(const ExactScene& scene, const GiNaC::matrix& eps);

/// eq. (12) before r: R_k (absolute rotation).
GiNaC::matrix absolute_rotation_matrix(const ExactScene& scene);

/// eq. (15): p_k - p_0 - eps (relative translation, Sec. 2.1 and App. A.2 agree).
GiNaC::matrix relative_translation(const ExactScene& scene, const GiNaC::matrix& eps);

/// Sec. 2.1 before r: R_0^T R_k (relative rotation as Sec. 2.1 defines it).
GiNaC::matrix relative_rotation_matrix(const ExactScene& scene);

/// eq. (17): r(R_k) - r(R_0) - eps (relative rotation as App. A.2 eq. (14) defines it).
/// Exact witnesses only (see exact_rotation_vector()).
GiNaC::matrix relative_diff_rotation(const ExactScene& scene, const GiNaC::matrix& eps);

/// eq. (22): R_0^T (p_k - p_0) - eps (hand-centric translation).
GiNaC::matrix hand_centric_translation(const ExactScene& scene, const GiNaC::matrix& eps);

/// eq. (25) before r: R_0^T R_k (hand-centric rotation).
GiNaC::matrix hand_centric_rotation_matrix(const ExactScene& scene);

/// eq. (3): T_0^{-1} T_{-h}, its 12 entries (hand-centric proprioception).
GiNaC::matrix hand_centric_proprioception(const ExactScene& scene);

/// Lemma 2's inner-policy input: [T_0^{-1} T_{-h} (12 entries); eye-in-hand point].
GiNaC::matrix inner_policy_input(const ExactScene& scene);

/// Lemma 2 without its eye-in-hand assumption: [T_0^{-1} T_{-h}; world point as is].
GiNaC::matrix inner_policy_input_third_person(const ExactScene& scene);

/// eq. (29): R_k^T (p_k - eps) (ActionFlow's translation flow, Funk et al. [8] eq. (3)).
GiNaC::matrix actionflow_translation(const ExactScene& scene, const GiNaC::matrix& eps);

}  // namespace handcentric::proofs::flows
