#pragma once
// The velocity field of a trained c8flow head, exposed for checks (tests, reports):
//
//   F(x, o, t) = 1/8 sum_{k=0..7} (g_k)_* f(g_k^{-1} x, g_k^{-1} o, t)      (frame averaging)
//
// with f the network's raw-coordinate velocity and g_k = R_z(k pi/4) acting as in c8_action.hpp.
// F(g x, g o, t) = g_* F(x, o, t) exactly for g in C8 (up to float rounding of the network);
// F is NOT translation-equivariant: the group fixes the world origin.
#include <Eigen/Core>

#include "handcentric/policy/head.hpp"

namespace handcentric::policy {

/// F (symmetrized = true) or the plain network field f (symmetrized = false) at raw absolute
/// action x and raw absolute observation o. Throws InvalidArgument if `head` is not a c8flow head.
Eigen::VectorXd c8_velocity(const Head& head, const Eigen::VectorXd& x, const Eigen::VectorXd& o,
                            double t, bool symmetrized);

}  // namespace handcentric::policy
