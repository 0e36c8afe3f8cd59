// SO(3): exp/log accuracy over the whole angle range, the canonical sign at pi, validation.
#include <catch2/catch.hpp>

#include "throws.hpp"  // tests/support
#include <cmath>
#include <numbers>
#include <random>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/rotation.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/core/so3.hpp"
#include "handcentric/props/catch.hpp"
#include "handcentric/props/observation/generators.hpp"
#include "handcentric/props/show.hpp"
#include "mutants.hpp"
#include "worst_error.hpp"  // tests/support

using namespace handcentric;
using LogFn = Eigen::Vector3d (*)(const Eigen::Matrix3d&);
constexpr double kPi = std::numbers::pi;

namespace {

// max over n rotations of |exp(log(R)) - R|_F, the rotations drawn by `draw`.
template <typename Draw>
double max_exp_log_error(LogFn log_fn, int n, std::uint64_t seed, Draw draw) {
  std::mt19937_64 rng(seed);
  double worst = 0.0;
  for (int i = 0; i < n; ++i) {
    const Eigen::Matrix3d R = draw(rng).matrix();
    worst = test::worst_of(worst, (so3::exp(log_fn(R)) - R).norm());
  }
  return worst;
}

Rotation haar(std::mt19937_64& rng) {
  return random_rotation(rng);
}
Rotation near_pi(std::mt19937_64& rng) {
  return random_rotation_with_angle(rng, kPi - 1e-10 * uniform01(rng));
}
Rotation near_zero(std::mt19937_64& rng) {
  return random_rotation_with_angle(rng, 1e-10 * uniform01(rng));
}

// log(exp(r)) = r for |r| <= pi - 1e-9, as a RapidCheck property on `log_fn`.
auto log_exp_roundtrip(LogFn log_fn) {
  return [log_fn] {
    const auto axis_u = *rc::gen::inRange(0, 1 << 30);
    const auto axis_v = *rc::gen::inRange(0, 1 << 30);
    // angles over [0, pi - 1e-9]: uniform, within 1e-6 of the top end, or below 1e-8
    const double u = *rc::gen::inRange(0, (1 << 30) + 1) / double(1 << 30);
    const int regime = *rc::gen::inRange(0, 3);
    const double top = kPi - 1e-9;
    const double angle = regime == 0 ? top * u : regime == 1 ? top - 1e-6 * u : 1e-8 * u;
    const Eigen::Vector3d r =
        angle * sphere_point(axis_u / double(1 << 30), axis_v / double(1 << 30));
    const Eigen::Vector3d back = log_fn(so3::exp(r));
    RC_ASSERT((back - r).norm() <= 1e-12);
  };
}

// Rotation by pi about unit axis v, built exactly as 2 v v^T - I (symmetric: no sign in it).
Eigen::Matrix3d half_turn(const Eigen::Vector3d& v) {
  return 2.0 * v * v.transpose() - Eigen::Matrix3d::Identity();
}

// Whether log_fn returns the canonical sign on a set of exact half turns.
bool canonical_at_pi(LogFn log_fn) {
  const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> cases = {
      // axis given -> canonical axis (largest-magnitude component positive, first on ties)
      {{1, 0, 0}, {1, 0, 0}},
      {{-1, 0, 0}, {1, 0, 0}},
      {{0, -1, 0}, {0, 1, 0}},
      {{0, 0, -1}, {0, 0, 1}},
      {{0, 0.6, -0.8}, {0, -0.6, 0.8}},
      {{-0.6, 0.8, 0}, {-0.6, 0.8, 0}},
      {{0.48, -0.6, -0.64}, {-0.48, 0.6, 0.64}},
  };
  for (const auto& [axis, canonical] : cases) {
    if ((log_fn(half_turn(axis)) - kPi * canonical).norm() > 1e-12) return false;
  }
  return true;
}

}  // namespace

TEST_CASE("exp_of_log_is_identity_on_a_million_haar_rotations", "[unit]") {
  CHECK(max_exp_log_error(test::real_log, 1'000'000, 1, haar) <= 1e-12);
}

TEST_CASE("exp_of_log_is_identity_within_1e-10_of_pi_and_of_0", "[unit]") {
  CHECK(max_exp_log_error(test::real_log, 100'000, 2, near_pi) <= 1e-12);
  CHECK(max_exp_log_error(test::real_log, 100'000, 3, near_zero) <= 1e-12);
}

TEST_CASE("mutant_naive_acos_log_fails_exp_of_log_near_pi_and_0", "[unit]") {
  CHECK(max_exp_log_error(test::naive_log, 100'000, 2, near_pi) > 1e-12);
  CHECK(max_exp_log_error(test::naive_log, 100'000, 3, near_zero) > 1e-12);
}

TEST_CASE("log_of_exp_is_identity_below_pi_minus_1e-9", "[property]") {
  props::require_property("log(exp(r)) = r", log_exp_roundtrip(test::real_log));
}

TEST_CASE("mutant_naive_log_falsifies_log_of_exp", "[property]") {
  props::require_falsified("naive log(exp(r)) = r", log_exp_roundtrip(test::naive_log));
}

TEST_CASE("log_at_exactly_pi_returns_the_canonical_sign", "[unit]") {
  CHECK(canonical_at_pi(test::real_log));
  CHECK_FALSE(canonical_at_pi(test::flipped_sign_log));  // planted fault is caught
}

TEST_CASE("log_just_below_pi_keeps_the_sign_of_the_rotation", "[unit]") {
  // exp((pi - 1e-9) v) and exp((pi - 1e-9)(-v)) are different rotations: log must tell them apart.
  const Eigen::Vector3d v = Eigen::Vector3d(0.48, -0.6, -0.64);
  for (double sign : {1.0, -1.0}) {
    const Eigen::Vector3d r = sign * (kPi - 1e-9) * v;
    CHECK((so3::log(so3::exp(r)) - r).norm() <= 1e-12);
  }
}

TEST_CASE("rotation_constructors_reject_bad_input_with_the_value_in_the_message", "[unit]") {
  Eigen::Matrix3d nan_matrix = Eigen::Matrix3d::Identity();
  nan_matrix(1, 2) = std::nan("");
  HC_CHECK_THROWS(Rotation::from_matrix(nan_matrix), InvalidRotation,
                  Catch::Matchers::Contains("non-finite") && Catch::Matchers::Contains("nan"));

  Eigen::Matrix3d skewed = Eigen::Matrix3d::Identity();
  skewed(0, 1) = 1e-6;
  HC_CHECK_THROWS(Rotation::from_matrix(skewed), InvalidRotation,
                  Catch::Matchers::Contains("not orthonormal") &&
                      Catch::Matchers::Contains("9.99999999") &&
                      Catch::Matchers::Contains("Rotation::nearest"));

  const Eigen::Matrix3d reflection = Eigen::Vector3d(1, 1, -1).asDiagonal();
  HC_CHECK_THROWS(Rotation::from_matrix(reflection), InvalidRotation,
                  Catch::Matchers::Contains("det(R) = -1"));

  HC_CHECK_THROWS(Rotation::from_quaternion(0, 0, 0, 0), InvalidRotation,
                  Catch::Matchers::Contains("zero") && Catch::Matchers::Contains("[0, 0, 0, 0]"));
  CHECK_THROWS_AS(Rotation::from_quaternion(1, std::numeric_limits<double>::infinity(), 0, 0),
                  InvalidRotation);
  CHECK_THROWS_AS(Rotation::exp(Eigen::Vector3d(std::nan(""), 0, 0)), InvalidRotation);
  CHECK_THROWS_AS(Rotation::about_z(std::numeric_limits<double>::infinity()), InvalidRotation);
  CHECK_THROWS_AS(Rotation::nearest(Eigen::Matrix3d::Zero()), InvalidRotation);
}

TEST_CASE("rotation_accepts_rotations_and_nearest_repairs_rounding", "[unit]") {
  std::mt19937_64 rng(7);
  const Rotation R = random_rotation(rng);
  CHECK_NOTHROW(Rotation::from_matrix(R.matrix()));
  Eigen::Matrix3d rounded = R.matrix();
  rounded(0, 0) += 1e-6;
  CHECK_THROWS_AS(Rotation::from_matrix(rounded), InvalidRotation);
  CHECK(distance(Rotation::nearest(rounded), R) < 2e-6);
  CHECK_NOTHROW(Rotation::from_matrix(Rotation::nearest(rounded).matrix()));
}
