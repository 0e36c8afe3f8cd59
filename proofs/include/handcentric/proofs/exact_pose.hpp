#pragma once
// Exact SE(3) arithmetic on GiNaC expressions: a pose [R | p] whose entries are symbols,
// rational functions of symbols, or exact numbers (rationals, sqrt(3), Pi). Nothing rounds.
//
// The same code serves both kinds of certificate: with symbolic entries it proves identities,
// with rational entries it evaluates exact counterexamples.
//
// inverse() uses R^T for R^{-1}: this is exact only for a matrix with R^T R = I, which every
// rotation built in quaternion_rotation.hpp satisfies identically (and rational_rotation.hpp
// checks exactly).
#include <ginac/ginac.h>

#include <string>
#include <vector>

namespace handcentric::proofs {

/// A 3x1 column of expressions.
GiNaC::matrix column(const GiNaC::ex& x, const GiNaC::ex& y, const GiNaC::ex& z);

/// [top; bottom]: two columns stacked.
GiNaC::matrix stack(const GiNaC::matrix& top, const GiNaC::matrix& bottom);

/// The 3x3 identity.
GiNaC::matrix identity3();

/// world_T_body = [R | p] with exact entries.
struct ExactPose {
  GiNaC::matrix R = identity3();      ///< 3x3 rotation part
  GiNaC::matrix p = column(0, 0, 0);  ///< 3x1 translation part

  /// (R R', R p' + p)
  ExactPose operator*(const ExactPose& other) const;
  /// R x + p
  GiNaC::matrix operator*(const GiNaC::matrix& point) const;
  /// (R^T, -R^T p): the inverse, given R^T R = I.
  ExactPose inverse() const;
  /// The 12 entries as one column: R row by row, then p.
  GiNaC::matrix entries() const;
};

/// An exact expression as deterministic text: terms and factors sorted by their text
/// (GiNaC's own order depends on the process), e.g. "-1/2*Pi + 2/9*Pi*sqrt(3)".
std::string canonical_text(const GiNaC::ex& value);

/// A matrix as [[a, b], [c, d]] with canonical entries.
std::string matrix_text(const GiNaC::matrix& m);

/// A column as "(a, b, c)" and a pose as "[R | p]" with exact entries ("I" for R = identity),
/// as printed in counterexample witnesses.
std::string column_text(const GiNaC::matrix& v);
std::string pose_text(const ExactPose& pose);

/// A pure translation [I | p].
ExactPose translation_pose(const GiNaC::matrix& p);
/// A pure rotation [R | 0].
ExactPose rotation_pose(const GiNaC::matrix& R);

/// The exact counterpart of core's Scene (same conventions): history[0] = T_0, history[h] = T_{-h},
/// chunk[k-1] = T_k, world-frame points, eye-in-hand points (in the frame of T_0).
struct ExactScene {
  std::vector<ExactPose> history;
  std::vector<ExactPose> chunk;
  std::vector<GiNaC::matrix> world_points;
  std::vector<GiNaC::matrix> hand_points;
};

/// g * scene as in Sec. 2.2: every pose T -> g T, every world point x -> g x; eye-in-hand points
/// stay (the camera, the hand and the objects move together).
ExactScene operator*(const ExactPose& g, const ExactScene& scene);

}  // namespace handcentric::proofs
