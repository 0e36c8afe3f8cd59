#include "handcentric/proofs/rational_rotation.hpp"

#include <string>

#include "handcentric/core/errors.hpp"
#include "handcentric/proofs/quaternion_rotation.hpp"

namespace handcentric::proofs {
namespace {

bool is_rational(const GiNaC::ex& value) {
  return GiNaC::is_a<GiNaC::numeric>(value) && GiNaC::ex_to<GiNaC::numeric>(value).is_rational();
}

}  // namespace

GiNaC::matrix rational_rotation(long w, long x, long y, long z) {
  if (w == 0 && x == 0 && y == 0 && z == 0) {
    throw InvalidRotation(
        "rational_rotation: the quaternion (0, 0, 0, 0) is not a rotation; "
        "give at least one nonzero integer component");
  }
  return quaternion_rotation(w, x, y, z);
}

GiNaC::matrix quarter_turn(int axis, int n) {
  if (axis < 0 || axis > 2) {
    throw InvalidArgument("quarter_turn: axis " + std::to_string(axis) +
                          " is not a coordinate axis; use 0 (x), 1 (y) or 2 (z)");
  }
  const int turns = ((n % 4) + 4) % 4;
  const int c = turns == 0 ? 1 : turns == 2 ? -1 : 0;  // cos(n pi / 2)
  const int s = turns == 1 ? 1 : turns == 3 ? -1 : 0;  // sin(n pi / 2)
  const int i = (axis + 1) % 3;
  const int j = (axis + 2) % 3;
  GiNaC::matrix R = identity3();
  R(i, i) = c;
  R(i, j) = -s;
  R(j, i) = s;
  R(j, j) = c;
  return R;
}

bool is_rational_column(const GiNaC::matrix& v) {
  for (unsigned i = 0; i < v.rows(); ++i) {
    for (unsigned j = 0; j < v.cols(); ++j) {
      if (!is_rational(v(i, j))) return false;
    }
  }
  return true;
}

bool is_exact_rotation(const GiNaC::matrix& R) {
  if (R.rows() != 3 || R.cols() != 3 || !is_rational_column(R)) return false;
  const GiNaC::matrix gram = R.transpose().mul(R);
  for (unsigned i = 0; i < 3; ++i) {
    for (unsigned j = 0; j < 3; ++j) {
      if (!(gram(i, j) - (i == j ? 1 : 0)).is_zero()) return false;
    }
  }
  return (R.determinant() - 1).is_zero();
}

bool has_angle_below_pi(const GiNaC::matrix& R) {
  if (!is_rational_column(R)) return false;
  return GiNaC::ex_to<GiNaC::numeric>(R.trace()) > -1;
}

GiNaC::matrix exact_rotation_vector(const GiNaC::matrix& R) {
  if (!is_exact_rotation(R)) {
    throw InvalidRotation("exact_rotation_vector: " + matrix_text(R) +
                          " is not an exact rational rotation (R^T R = I, det R = 1); build it "
                          "with rational_rotation() or quarter_turn()");
  }
  const GiNaC::ex cos_phi = (R.trace() - 1) / 2;
  GiNaC::ex phi;
  if (cos_phi == 1) return column(0, 0, 0);
  if (cos_phi == GiNaC::numeric(1, 2)) {
    phi = GiNaC::Pi / 3;
  } else if (cos_phi == 0) {
    phi = GiNaC::Pi / 2;
  } else if (cos_phi == GiNaC::numeric(-1, 2)) {
    phi = 2 * GiNaC::Pi / 3;
  } else {
    throw InvalidArgument("exact_rotation_vector: cos(angle) = " + canonical_text(cos_phi) +
                          " has no exact angle here; use a rotation with cos(angle) in "
                          "{1, 1/2, 0, -1/2} (angle pi is refused: r(R) is not unique there)");
  }
  const GiNaC::ex sin_phi =
      GiNaC::sqrt(GiNaC::ex(1) - cos_phi * cos_phi);  // > 0 for phi in (0, pi)
  // r = phi / (2 sin phi) * vee(R - R^T), the axis-angle vector of Euler's theorem.
  const GiNaC::ex scale = phi / (2 * sin_phi);
  return column(GiNaC::normal(scale * (R(2, 1) - R(1, 2))),
                GiNaC::normal(scale * (R(0, 2) - R(2, 0))),
                GiNaC::normal(scale * (R(1, 0) - R(0, 1))));
}

}  // namespace handcentric::proofs
