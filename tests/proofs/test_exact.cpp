// Exact arithmetic: rational rotations are exact rotations, exact rotation vectors agree with
// core's floating-point log, and bad input is a typed error naming the value.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>

#include "handcentric/core/errors.hpp"
#include "throws.hpp"
#include "handcentric/core/rotation.hpp"
#include "handcentric/core/so3.hpp"
#include "handcentric/proofs/certificate.hpp"
#include "handcentric/proofs/quaternion_rotation.hpp"
#include "handcentric/proofs/rational_rotation.hpp"

using namespace handcentric;
using namespace handcentric::proofs;

namespace {

Eigen::MatrixXd to_double(const GiNaC::matrix& m) {
  Eigen::MatrixXd out(m.rows(), m.cols());
  for (unsigned i = 0; i < m.rows(); ++i) {
    for (unsigned j = 0; j < m.cols(); ++j) {
      out(i, j) = GiNaC::ex_to<GiNaC::numeric>(GiNaC::evalf(m(i, j))).to_double();
    }
  }
  return out;
}

// The 24 rotations of the cube: products of quarter turns about x, y, z.
std::vector<GiNaC::matrix> cube_rotations() {
  std::vector<GiNaC::matrix> all;
  for (int a = 0; a < 4; ++a) {
    for (int b = 0; b < 4; ++b) {
      for (int c = 0; c < 4; ++c) {
        const GiNaC::matrix R = quarter_turn(0, a).mul(quarter_turn(1, b)).mul(quarter_turn(2, c));
        bool seen = false;
        for (const GiNaC::matrix& S : all) seen = seen || S.sub(R).evalm().is_zero_matrix();
        if (!seen) all.push_back(R);
      }
    }
  }
  return all;
}

// How many cube rotations of angle below pi have exact_rotation_vector-like `log` different
// from core's so3::log by more than 1e-14 (the floating-point log's rounding).
template <typename Log>
int disagreements_with_core_log(Log log) {
  int disagreements = 0;
  for (const GiNaC::matrix& R : cube_rotations()) {
    if ((R.trace() + 1).is_zero()) continue;  // angle pi: refused, r not unique
    const Eigen::Vector3d exact = to_double(log(R));
    const Eigen::Vector3d rounded = so3::log(to_double(R));
    if ((exact - rounded).norm() > 1e-14) ++disagreements;
  }
  return disagreements;
}

}  // namespace

TEST_CASE("integer_quaternions_give_exact_rational_rotations", "[proofs]") {
  for (const auto& q :
       std::vector<std::array<long, 4>>{{2, 1, 0, 0}, {1, 1, 1, 1}, {3, -1, 2, 5}, {0, 0, 0, 7}}) {
    CHECK(is_exact_rotation(rational_rotation(q[0], q[1], q[2], q[3])));
  }
  CHECK(cube_rotations().size() == 24);
  for (const GiNaC::matrix& R : cube_rotations()) CHECK(is_exact_rotation(R));
  // Planted faults: M(q) without the division by |q|^2, and a reflection, are not rotations.
  CHECK_FALSE(is_exact_rotation(rational_rotation(2, 1, 0, 0).mul_scalar(5)));
  CHECK_FALSE(is_exact_rotation(GiNaC::matrix{{1, 0, 0}, {0, 1, 0}, {0, 0, -1}}));
}

TEST_CASE("generic_quaternion_rotation_is_orthonormal_identically", "[proofs]") {
  const GiNaC::matrix R = generic_rotation("q");
  const GiNaC::matrix gram = R.transpose().mul(R);
  for (unsigned i = 0; i < 3; ++i) {
    for (unsigned j = 0; j < 3; ++j) CHECK(GiNaC::normal(gram(i, j) - (i == j ? 1 : 0)).is_zero());
  }
  CHECK(GiNaC::normal(R.determinant() - 1).is_zero());
  // Planted fault: the same matrix without 1/|q|^2 is not orthonormal.
  const GiNaC::ex w = GiNaC::symbol("w");
  const GiNaC::matrix M = quaternion_rotation(w, 1, 0, 0).mul_scalar(w * w + 1);
  CHECK_FALSE(GiNaC::normal(M.transpose().mul(M)(0, 0) - 1).is_zero());
}

TEST_CASE("rational_rotations_match_core_quaternion_convention", "[proofs]") {
  for (const auto& q :
       std::vector<std::array<long, 4>>{{2, 1, 0, 0}, {1, 1, 1, 1}, {3, -1, 2, 5}}) {
    const Eigen::Matrix3d exact = to_double(rational_rotation(q[0], q[1], q[2], q[3]));
    const Eigen::Matrix3d core =
        Rotation::from_quaternion(static_cast<double>(q[0]), static_cast<double>(q[1]),
                                  static_cast<double>(q[2]), static_cast<double>(q[3]))
            .matrix();
    CHECK((exact - core).norm() < 1e-15);
    // Planted fault: the transposed convention differs from core's.
    CHECK((Eigen::Matrix3d(exact.transpose()) - core).norm() > 0.1);
  }
}

TEST_CASE("angle_below_pi_is_decided_exactly_from_the_trace", "[proofs]") {
  CHECK(has_angle_below_pi(rational_rotation(2, 0, 0, 1)));
  CHECK(has_angle_below_pi(quarter_turn(0, 1).mul(quarter_turn(2, 1))));  // 2 pi / 3
  // Planted faults: a half turn, and a rotation by pi about (1, 1, 0) from q = (0, 1, 1, 0).
  CHECK_FALSE(has_angle_below_pi(quarter_turn(2, 2)));
  CHECK_FALSE(has_angle_below_pi(rational_rotation(0, 1, 1, 0)));
}

TEST_CASE("exact_rotation_vectors_match_core_log_on_the_cube_rotations", "[proofs]") {
  CHECK(disagreements_with_core_log(
            [](const GiNaC::matrix& R) { return exact_rotation_vector(R); }) == 0);
  const GiNaC::matrix r = exact_rotation_vector(quarter_turn(0, 1).mul(quarter_turn(2, 1)));
  CHECK(GiNaC::normal(r(0, 0) - 2 * GiNaC::Pi / (3 * GiNaC::sqrt(GiNaC::ex(3)))).is_zero());
  // Planted fault: r with the opposite sign (vee(R^T - R)) disagrees with core.
  CHECK(disagreements_with_core_log(
            [](const GiNaC::matrix& R) { return exact_rotation_vector(R).mul_scalar(-1); }) > 0);
}

TEST_CASE("exact_constructors_reject_bad_input_naming_the_value", "[proofs]") {
  HC_CHECK_THROWS(rational_rotation(0, 0, 0, 0), InvalidRotation, Catch::Contains("(0, 0, 0, 0)"));
  HC_CHECK_THROWS(quarter_turn(3, 1), InvalidArgument, Catch::Contains("axis 3"));
  HC_CHECK_THROWS(exact_rotation_vector(GiNaC::matrix{{2, 0, 0}, {0, 1, 0}, {0, 0, 1}}),
                  InvalidRotation, Catch::Contains("[[2, 0, 0], [0, 1, 0], [0, 0, 1]]"));
  HC_CHECK_THROWS(exact_rotation_vector(rational_rotation(2, 0, 0, 1)), InvalidArgument,
                  Catch::Contains("3/5"));
  HC_CHECK_THROWS(exact_rotation_vector(quarter_turn(2, 2)), InvalidArgument,  // angle pi
                  Catch::Contains("= -1 "));
}

TEST_CASE("identity_check_decides_rational_functions_exactly_with_no_tolerance", "[proofs]") {
  const GiNaC::symbol a("a"), t("t"), w("w"), x("x");
  const GiNaC::ex n = w * w + x * x;
  CHECK(is_identically_zero((a - t * a) / (1 - t) - a));  // (1 - t) cancels
  CHECK(is_identically_zero((w * w - x * x) / n * (w * w - x * x) / n +
                            (2 * w * x) / n * (2 * w * x) / n - 1));  // cos^2 + sin^2 = 1
  CHECK(is_identically_zero(GiNaC::pow(GiNaC::sqrt(a), 2) - a));
  // Planted faults: a difference of 1e-30 a, or a sign error, is not zero.
  CHECK_FALSE(is_identically_zero((a - t * a) / (1 - t) - a +
                                  GiNaC::numeric(1, 1000000000) * GiNaC::numeric(1, 1000000000) *
                                      GiNaC::numeric(1, 1000000000) / GiNaC::numeric(1000) * a));
  CHECK_FALSE(is_identically_zero((w * w - x * x) / n * (w * w - x * x) / n -
                                  (2 * w * x) / n * (2 * w * x) / n - 1));
}
