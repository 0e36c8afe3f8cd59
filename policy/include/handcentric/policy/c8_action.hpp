#pragma once
// How the cyclic group C8 (rotations about world z by k * 45 deg, through the world origin) acts
// on ABSOLUTE vectors (representation.hpp layouts), for the C8-symmetrized flow, the analogue
// of Equivariant Diffusion Policy [7].
//
// A global rotation g = [R | 0] maps every world pose T -> g T (Sec. 2.2). On the absolute
// action vector, per step k: p_k -> R p_k and r_k -> log(R exp(r_k)) (the rotation vector of
// R R_k). On the absolute observation: the same on each past pose, world points x -> R x, and
// eye-in-hand points unchanged. A velocity v at a is carried to g a by the differential
//   translation: R v_p,   rotation: Jr(r')^{-1} Jr(r) v_r,  r' = log(R exp(r)),
// with Jr the right Jacobian of exp on SO(3): exp(r + d) = exp(r) exp(Jr(r) d) + O(d^2).
// The rotation-vector action is a group action on the open ball |r| < pi (where log(exp(r)) =
// r); a noisy vector outside it is wrapped into the ball first, as any rotation vector is.
#include <Eigen/Core>

namespace handcentric::policy::c8 {

/// R_z(k * pi / 4), for any integer k.
Eigen::Matrix3d rotation(int k);

/// Right Jacobian Jr(r) of exp on SO(3) and its inverse (accurate at r = 0 and at |r| = pi).
Eigen::Matrix3d right_jacobian(const Eigen::Vector3d& r);
Eigen::Matrix3d right_jacobian_inverse(const Eigen::Vector3d& r);

/// g a for an absolute action vector (length 6K). Throws InvalidArgument for a length that is
/// not a multiple of 6.
Eigen::VectorXd act_on_actions(const Eigen::Matrix3d& R, const Eigen::VectorXd& a);

/// g o for an absolute observation of H past poses (H + 1 blocks of 6), then `hand_points`
/// eye-in-hand points, then world points. Throws InvalidArgument for a length that does not fit.
Eigen::VectorXd act_on_observation(const Eigen::Matrix3d& R, const Eigen::VectorXd& o,
                                   int history_length, int hand_points);

/// The differential of a -> g a at `a`, applied to the velocity `v` (see above).
Eigen::VectorXd push_velocity(const Eigen::Matrix3d& R, const Eigen::VectorXd& a,
                              const Eigen::VectorXd& v);

}  // namespace handcentric::policy::c8
