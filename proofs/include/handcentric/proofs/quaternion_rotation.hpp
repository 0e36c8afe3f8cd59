#pragma once
// Rotations parametrized by a quaternion q = (w, x, y, z), exact for any entries:
//
//   R(q) = M(q) / |q|^2,   M(q) = [[w2+x2-y2-z2, 2(xy-wz), 2(xz+wy)],
//                                  [2(xy+wz), w2-x2+y2-z2, 2(yz-wx)],
//                                  [2(xz-wy), 2(yz+wx), w2-x2-y2+z2]]
//
// M(q)^T M(q) = |q|^4 I and det M(q) = |q|^6 hold as polynomial identities, so R(q)^T R(q) = I
// and det R(q) = 1 hold identically: with q four independent symbols, R(q) is a *generic*
// rotation (every rotation is R(q) for some q != 0), and an identity in q proved by rational
// simplification holds for every rotation. With integer q it is an exact rational rotation
// (a "Pythagorean" rotation, e.g. q = (2, 1, 0, 0) gives cos = 3/5, sin = 4/5).
#include <ginac/ginac.h>

#include <string>

#include "handcentric/proofs/exact_pose.hpp"

namespace handcentric::proofs {

/// R(q) = M(q) / |q|^2 (see above). No check: for symbols, |q|^2 != 0 is the generic case.
GiNaC::matrix quaternion_rotation(const GiNaC::ex& w, const GiNaC::ex& x, const GiNaC::ex& y,
                                  const GiNaC::ex& z);

/// Fresh symbols: a generic rotation R(q_name) with q_name = (name_w, name_x, name_y, name_z).
GiNaC::matrix generic_rotation(const std::string& name);

/// Fresh symbols: a generic vector (name_1, name_2, name_3).
GiNaC::matrix generic_vector(const std::string& name);

/// A generic pose [R(q) | p] with fresh symbols for q and p.
ExactPose generic_pose(const std::string& name);

}  // namespace handcentric::proofs
