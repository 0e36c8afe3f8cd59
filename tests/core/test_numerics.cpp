// Numerical robustness of the geometry (docs/RELIABILITY.md, item 5), as RapidCheck properties over
// generated inputs that reach the ends of double's range:
//   1. no geometry function returns a non-finite value for a valid input (rigid_transform.hpp
//      says which inputs are valid);
//   2. exp and log stay within their documented error (so3.hpp) everywhere, including at angle 0,
//      at pi and within 1e-12 of both;
//   3. validating constructors reject every non-finite, non-orthonormal or reflecting input with
//      a typed error whose message names the value.
// Each property runs on kNumericCases inputs (RC_PARAMS="max_success=N" overrides, and so does
// HANDCENTRIC_NUMERIC_CASES=N, which scripts/sanitize.sh uses; the long run in
// docs/RELIABILITY.md uses 1e7), and each is run on a planted fault that must fail it (the
// mutant_* cases; faults in mutants.hpp).
#include <catch2/catch.hpp>

#include <Eigen/LU>  // determinant
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <numbers>
#include <string>
#include <type_traits>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/rotation.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/core/so3.hpp"
#include "handcentric/props/catch.hpp"
#include "mutants.hpp"
#include "worst_error.hpp"  // tests/support

using namespace handcentric;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
// Translations up to this magnitude are valid input (rigid_transform.hpp).
constexpr double kMaxTranslation = 1e150;

// Every property here: 1e5 cases unless RC_PARAMS names max_success. These functions take
// ~100 ns, so a case costs what RapidCheck's generation costs (a few us).
constexpr int kNumericCases = 100'000;

props::PropertyParams numeric_params() {
  props::PropertyParams params = props::property_params();
  const char* rc_params = std::getenv("RC_PARAMS");
  if (rc_params != nullptr && std::strstr(rc_params, "max_success=") != nullptr) return params;
  params.cases = kNumericCases;
  if (const char* cases = std::getenv("HANDCENTRIC_NUMERIC_CASES")) {
    const int n = std::atoi(cases);
    if (n < 1)
      throw InvalidArgument(std::string("HANDCENTRIC_NUMERIC_CASES='") + cases +
                            "': give a positive number of cases");
    params.cases = n;
  }
  return params;
}

template <typename Testable>
void require_numeric_property(const std::string& description, Testable&& testable) {
  const props::PropertyParams params = numeric_params();
  const props::PropertyOutcome outcome =
      props::run_property(description, std::forward<Testable>(testable), params);
  INFO(description << "\n" << outcome.message);
  REQUIRE(outcome.passed);
  CHECK(outcome.cases >= params.cases);
}

// ---- generated inputs ----

// A number in [0, 1] from 30 random bits (shrinks to 0).
double unit() {
  return *rc::gen::inRange(0, (1 << 30) + 1) / double(1 << 30);
}

// 10^e for e uniform in [lo, hi].
double decade(double lo, double hi) {
  return std::pow(10.0, lo + (hi - lo) * unit());
}

double random_sign() {
  return *rc::gen::inRange(0, 2) == 0 ? 1.0 : -1.0;
}

// A unit axis: a coordinate axis (either sign) or uniform on the sphere.
Eigen::Vector3d axis() {
  const int kind = *rc::gen::inRange(0, 4);
  if (kind < 3) {
    Eigen::Vector3d e = Eigen::Vector3d::Zero();
    e(kind) = random_sign();
    if (*rc::gen::inRange(0, 2) == 0) return e;
  }
  return sphere_point(unit(), unit());
}

// The extremes of double and of float (the policy's network is float32: its outputs reach the
// geometry as doubles that are floats, up to FLT_MAX).
double extreme_number() {
  static const double values[] = {0.0,
                                  1.0,
                                  DBL_MAX,
                                  DBL_MIN,
                                  std::numeric_limits<double>::denorm_min(),
                                  DBL_EPSILON,
                                  FLT_MAX,
                                  FLT_MIN,
                                  std::numeric_limits<float>::denorm_min(),
                                  FLT_EPSILON,
                                  kPi,
                                  2.0 * kPi,
                                  static_cast<float>(kPi)};
  constexpr int count = sizeof(values) / sizeof(values[0]);
  return random_sign() * values[*rc::gen::inRange(0, count)];
}

// A finite rotation vector: the angle is 0, tiny (down to 1e-300), within 1e-12 of 0, uniform in
// [0, pi], within 1e-12 of pi, pi's two neighbouring doubles, past pi (wraps), huge (up to
// 1e308), or each component an extreme of double or float (|r| may exceed DBL_MAX).
Eigen::Vector3d rotation_vector() {
  switch (*rc::gen::inRange(0, 10)) {
    case 0:
      return Eigen::Vector3d::Zero();
    case 1:
      return decade(-300, -12) * axis();
    case 2:
      return 1e-12 * unit() * axis();
    case 3:
      return kPi * unit() * axis();
    case 4:
      return (kPi - 1e-12 * unit()) * axis();
    case 5:
      return (*rc::gen::inRange(0, 2) == 0 ? kPi : std::nextafter(kPi, 4.0)) * axis();
    case 6:
      return (kPi + 1e6 * unit()) * axis();
    case 7:
      return decade(6, 308) * axis();
    case 8:
      return Eigen::Vector3d(extreme_number(), extreme_number(), extreme_number());
    default:
      return (kPi - decade(-16, -12)) * axis();
  }
}

// A valid translation: zero, each coordinate of magnitude 1e-300..1e150, uniform in [-10, 10],
// or extremes of float (FLT_MAX and the subnormals among them).
Eigen::Vector3d translation() {
  Eigen::Vector3d p;
  switch (*rc::gen::inRange(0, 4)) {
    case 0:
      return Eigen::Vector3d::Zero();
    case 1:
      for (int i = 0; i < 3; ++i) p(i) = random_sign() * decade(-300, 150);
      return p;
    case 2:
      for (int i = 0; i < 3; ++i) p(i) = 20.0 * unit() - 10.0;
      return p;
    default:
      for (int i = 0; i < 3; ++i) {
        const double x = extreme_number();
        p(i) = std::abs(x) <= kMaxTranslation ? x : std::copysign(FLT_MAX, x);
      }
      return p;
  }
}

// A nonzero quaternion of norm 1e-300..1e300 (or an axis quaternion).
Eigen::Vector4d quaternion() {
  Eigen::Vector4d q;
  for (int i = 0; i < 4; ++i) q(i) = 2.0 * unit() - 1.0;
  if (!(q.cwiseAbs().maxCoeff<Eigen::PropagateNaN>() > 0.0)) q(0) = 1.0;
  return decade(-300, 300) * q;
}

bool finite(const Rotation& R) {
  return R.matrix().allFinite();
}
bool finite(const RigidTransform& T) {
  return T.rotation().matrix().allFinite() && T.translation().allFinite();
}

double orthonormality_error(const Eigen::Matrix3d& R) {
  return (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
}

// Whether Rotation::from_matrix accepts R (a result must be a rotation, not just finite).
bool is_valid_rotation(const Eigen::Matrix3d& R) {
  try {
    Rotation::from_matrix(R);
    return true;
  } catch (const InvalidRotation&) {
    return false;
  }
}

// ---- property 1: finite outputs ----

struct Geometry {
  Eigen::Matrix3d (*so3_exp)(const Eigen::Vector3d&);
  RigidTransform (*se3_exp)(const Twist&);
};

RigidTransform real_se3_exp(const Twist& twist) {
  return RigidTransform::exp(twist);
}
const Geometry kReal{so3::exp, real_se3_exp};

auto finite_on_valid_input(Geometry geometry) {
  return [geometry] {
    const Eigen::Vector3d r = rotation_vector(), omega = rotation_vector();
    const Eigen::Vector3d p = translation(), rho = translation(), x = translation();

    const Eigen::Matrix3d M = geometry.so3_exp(r);
    RC_ASSERT(M.allFinite());
    RC_ASSERT(is_valid_rotation(M));
    const Rotation R = Rotation::from_matrix(M);
    const Rotation S = Rotation::exp(omega);
    RC_ASSERT(so3::log(M).allFinite());
    RC_ASSERT(std::isfinite(so3::angle(M)));
    RC_ASSERT(R.log().allFinite());
    RC_ASSERT(finite(R * S));
    RC_ASSERT(finite(R.inverse()));
    RC_ASSERT(finite(R.inverse_compose(S)));
    RC_ASSERT((R * x).allFinite());
    RC_ASSERT(std::isfinite(distance(R, S)));

    Twist twist;
    twist << rho, omega;
    const RigidTransform E = geometry.se3_exp(twist);
    RC_ASSERT(finite(E));
    RC_ASSERT(is_valid_rotation(E.rotation().matrix()));
    const RigidTransform T(R, p), U(S, rho);
    RC_ASSERT(T.log().allFinite());
    RC_ASSERT(finite(T.inverse()));
    RC_ASSERT(finite(T * U));
    RC_ASSERT(finite(T.inverse_compose(U)));
    RC_ASSERT((T * x).allFinite());
    RC_ASSERT(T.matrix().allFinite());
    RC_ASSERT(std::isfinite(distance(T, U)));

    const Eigen::Vector4d q = quaternion();
    const Rotation Q = Rotation::from_quaternion(q(0), q(1), q(2), q(3));
    RC_ASSERT(is_valid_rotation(Q.matrix()));
    const double theta = rotation_vector().x();
    RC_ASSERT(finite(RigidTransform::planar(theta, p.x(), p.y())));
    // the nearest rotation to a rotation of any scale, rounded
    const Eigen::Matrix3d rounded =
        decade(-300, 300) * (M + 1e-6 * Eigen::Matrix3d::Ones() * (unit() - 0.5));
    RC_ASSERT(is_valid_rotation(Rotation::nearest(rounded).matrix()));
  };
}

// ---- property 2: documented error of exp and log ----

struct LogUnderTest {
  Eigen::Vector3d (*log)(const Eigen::Matrix3d&);
};

auto within_documented_error(LogUnderTest under_test) {
  return [under_test] {
    const Eigen::Vector3d r = rotation_vector();
    const Eigen::Matrix3d R = so3::exp(r);
    RC_ASSERT(orthonormality_error(R) <= so3::kOrthonormalityError);
    RC_ASSERT(std::abs(R.determinant() - 1.0) <= so3::kOrthonormalityError);

    const Eigen::Vector3d back = under_test.log(R);
    RC_ASSERT(back.allFinite());
    RC_ASSERT(back.norm() <= kPi + so3::kAngleSlack);
    RC_ASSERT((so3::exp(back) - R).norm() <= so3::kRoundTripError);

    // |r| is finite below DBL_MAX; past it r wraps and only exp(log(R)) = R is promised.
    const double angle = r.stableNorm();  // no underflow for |r| ~ 1e-300
    if (angle <= kPi - so3::kSignAmbiguity) {
      RC_ASSERT((back - r).norm() <= so3::kRoundTripError * std::min(1.0, angle));
    } else if (angle <= kPi) {
      const Eigen::Vector3d antipode = -(2.0 * kPi - angle) / angle * r;
      RC_ASSERT(std::min((back - r).norm(), (back - antipode).norm()) <= so3::kRoundTripError);
    }

    // SE(3): exp(log(T)) = T for any valid T; log(exp(xi)) = xi below pi - kSignAmbiguity.
    const Eigen::Vector3d p = translation();
    const RigidTransform T = RigidTransform::unchecked(R, p);
    const Twist xi = T.log();
    RC_ASSERT(distance(RigidTransform::exp(xi), T) <= so3::kRoundTripError * (1.0 + p.norm()));
    if (angle <= kPi - so3::kSignAmbiguity) {
      Twist twist;
      twist << p, r;
      RC_ASSERT((RigidTransform::exp(twist).log() - twist).norm() <=
                so3::kRoundTripError * (1.0 + p.norm()));
    }
  };
}

// ---- property 3: validating constructors ----

using RotationValidator = Rotation (*)(const Eigen::Matrix3d&);
Rotation real_from_matrix(const Eigen::Matrix3d& M) {
  return Rotation::from_matrix(M);
}

// Certainly not orthonormal, also where R^T R is not computable (entries near 1e300 give inf -
// inf = nan): an orthonormal matrix has no entry above 1.
bool certainly_not_orthonormal(const Eigen::Matrix3d& M) {
  return M.cwiseAbs().maxCoeff<Eigen::PropagateNaN>() > 2.0 || orthonormality_error(M) > 1e-8;
}

enum class Kind { rotation, rounded_rotation, non_finite, non_orthonormal, reflection };

struct Candidate {
  Eigen::Matrix3d M;
  Kind kind;
};

// A matrix of a known kind. Rounded rotations are off by at most 1e-11 per entry (|R^T R - I|_F
// <= ~1e-10, under the 1e-9 tolerance); non-orthonormal ones are discarded unless they are off
// by more than 1e-8, so no case sits on the tolerance.
Candidate candidate() {
  const Eigen::Matrix3d R = so3::exp(rotation_vector());
  const auto random_matrix = [] {
    Eigen::Matrix3d noise;
    for (int i = 0; i < 9; ++i) noise(i) = 2.0 * unit() - 1.0;
    return noise;
  };
  switch (*rc::gen::inRange(0, 5)) {
    case 0:
      return {R, Kind::rotation};
    case 1:
      return {R + 1e-11 * random_matrix(), Kind::rounded_rotation};
    case 2: {
      Eigen::Matrix3d M =
          *rc::gen::inRange(0, 2) == 0 ? R : Eigen::Matrix3d(decade(-300, 300) * random_matrix());
      const double bad[] = {kNan, kInf, -kInf};
      M(*rc::gen::inRange(0, 9)) = bad[*rc::gen::inRange(0, 3)];
      if (*rc::gen::inRange(0, 4) == 0) M(*rc::gen::inRange(0, 9)) = bad[*rc::gen::inRange(0, 3)];
      return {M, Kind::non_finite};
    }
    case 3: {
      const int how = *rc::gen::inRange(0, 3);
      const Eigen::Matrix3d M = how == 0 ? Eigen::Matrix3d(R + decade(-8, 3) * random_matrix())
                                : how == 1
                                    ? Eigen::Matrix3d((1.0 + random_sign() * decade(-8, 2)) * R)
                                    : Eigen::Matrix3d(decade(-300, 300) * random_matrix());
      RC_PRE(M.allFinite() && certainly_not_orthonormal(M));
      return {M, Kind::non_orthonormal};
    }
    default: {
      const Eigen::Matrix3d flip = Eigen::Vector3d(1.0, 1.0, -1.0).asDiagonal();
      const Eigen::Matrix3d M =
          *rc::gen::inRange(0, 2) == 0 ? Eigen::Matrix3d(-R) : Eigen::Matrix3d(R * flip);
      if (*rc::gen::inRange(0, 2) == 0) return {M, Kind::reflection};
      return {M + 1e-11 * random_matrix(), Kind::reflection};
    }
  }
}

// `make` throws `Expected` (a handcentric::Error) whose message names the value: it contains
// `value` printed as format_matrix / format_number print it.
template <typename Expected, typename Make>
bool rejects(Make make, const std::string& value) {
  static_assert(std::is_base_of_v<Error, Expected>);
  try {
    make();
  } catch (const Expected& error) {
    return std::string(error.what()).find(value) != std::string::npos;
  } catch (...) {
    return false;
  }
  return false;
}
template <typename Expected, typename Make>
bool rejects(Make make, const Eigen::Ref<const Eigen::MatrixXd>& value) {
  return rejects<Expected>(make, format_matrix(value));
}

auto constructors_reject_invalid_input(RotationValidator validate) {
  return [validate] {
    const Candidate c = candidate();
    const bool valid = c.kind == Kind::rotation || c.kind == Kind::rounded_rotation;
    if (valid) {
      Eigen::Matrix3d accepted;
      try {
        accepted = validate(c.M).matrix();
      } catch (const std::exception& error) {
        RC_FAIL(std::string("a rotation was rejected: ") + error.what());
      }
      RC_ASSERT(accepted == c.M);
    } else {
      RC_ASSERT(rejects<InvalidRotation>([&] { validate(c.M); }, c.M));
    }

    // The same block in a homogeneous matrix, with a translation that may be non-finite and a
    // last row that may be wrong: non-finite anywhere or a wrong last row is InvalidTransform,
    // then a bad rotation block is InvalidRotation.
    Eigen::Matrix4d H = Eigen::Matrix4d::Identity();
    H.topLeftCorner<3, 3>() = c.M;
    H.topRightCorner<3, 1>() = translation();
    const int damage = *rc::gen::inRange(0, 4);
    if (damage == 1) H(*rc::gen::inRange(0, 3), 3) = *rc::gen::inRange(0, 2) == 0 ? kNan : -kInf;
    if (damage == 2) H(3, *rc::gen::inRange(0, 4)) += 0.5;
    const bool finite_everywhere = H.allFinite();
    if (!finite_everywhere || damage == 2) {
      RC_ASSERT(rejects<InvalidTransform>([&] { RigidTransform::from_matrix(H); }, H));
    } else if (!valid) {
      RC_ASSERT(rejects<InvalidRotation>([&] { RigidTransform::from_matrix(H); }, c.M));
    } else {
      RC_ASSERT(RigidTransform::from_matrix(H).matrix() == H);
    }

    // One of the other validating constructors, on a non-finite value wherever it sits.
    const double bad = (*rc::gen::inRange(0, 3) == 0 ? kNan : random_sign() * kInf);
    const auto with_bad = [bad](auto v) {
      v(*rc::gen::inRange(0, static_cast<int>(v.size()))) = bad;
      return v;
    };
    switch (*rc::gen::inRange(0, 8)) {
      case 0: {
        const Eigen::Vector3d v = with_bad(translation());
        RC_ASSERT(rejects<InvalidTransform>([&] { RigidTransform(Rotation(), v); }, v));
        break;
      }
      case 1: {
        const Eigen::Vector3d v = with_bad(rotation_vector());
        RC_ASSERT(rejects<InvalidRotation>([&] { Rotation::exp(v); }, v));
        break;
      }
      case 2: {
        Twist twist;
        twist << translation(), rotation_vector();
        twist = with_bad(twist);
        RC_ASSERT(rejects<InvalidTransform>([&] { RigidTransform::exp(twist); }, twist));
        break;
      }
      case 3: {
        const Eigen::Vector4d q = with_bad(quaternion());
        RC_ASSERT(rejects<InvalidRotation>(
            [&] { Rotation::from_quaternion(q(0), q(1), q(2), q(3)); }, q));
        break;
      }
      case 4:
        RC_ASSERT(rejects<InvalidRotation>([&] { Rotation::from_quaternion(0.0, 0.0, 0.0, 0.0); },
                                           Eigen::Vector4d::Zero()));
        break;
      case 5:
        RC_ASSERT(rejects<InvalidRotation>([&] { Rotation::about_z(bad); }, format_number(bad)));
        break;
      case 6:
        RC_ASSERT(rejects<InvalidRotation>([&] { RigidTransform::planar(bad, 0.0, 0.0); },
                                           format_number(bad)));
        break;
      default:
        RC_ASSERT(rejects<InvalidTransform>([&] { RigidTransform::planar(0.0, 1.0, bad); },
                                            Eigen::Vector3d(1.0, bad, 0.0)));
    }
    if (!c.M.allFinite()) RC_ASSERT(rejects<InvalidRotation>([&] { Rotation::nearest(c.M); }, c.M));
  };
}

}  // namespace

TEST_CASE("numerics_geometry_is_finite_on_every_valid_input", "[property]") {
  require_numeric_property("every geometry function is finite on valid input",
                           finite_on_valid_input(kReal));
}

TEST_CASE("mutant_numerics_textbook_so3_exp_is_not_finite_on_huge_or_tiny_vectors", "[property]") {
  props::require_falsified("textbook so3 exp is finite",
                           finite_on_valid_input({test::textbook_exp, real_se3_exp}));
}

TEST_CASE("mutant_numerics_textbook_se3_exp_is_not_finite_on_huge_rotations", "[property]") {
  props::require_falsified("textbook se3 exp is finite",
                           finite_on_valid_input({so3::exp, test::textbook_se3_exp}));
}

TEST_CASE("numerics_exp_and_log_stay_within_their_documented_error", "[property]") {
  require_numeric_property("exp and log within so3.hpp's bounds",
                           within_documented_error({test::real_log}));
}

TEST_CASE("mutant_numerics_naive_log_leaves_the_documented_error", "[property]") {
  props::require_falsified("naive log within the bounds",
                           within_documented_error({test::naive_log}));
}

TEST_CASE("numerics_validating_constructors_reject_invalid_input_with_a_typed_error",
          "[property]") {
  require_numeric_property("constructors reject invalid input",
                           constructors_reject_invalid_input(real_from_matrix));
}

TEST_CASE("mutant_numerics_a_validator_without_a_finiteness_check_accepts_nan", "[property]") {
  props::require_falsified("lenient validator rejects invalid input",
                           constructors_reject_invalid_input(test::lenient_from_matrix));
}

TEST_CASE("format_shortest_reads_back_exactly_and_is_as_short_as_typed", "[unit]") {
  CHECK(format_shortest(0.3) == "0.3");
  CHECK(format_shortest(25.0) == "25");
  CHECK(format_shortest(-1e-300) == "-1e-300");
  CHECK(format_shortest(std::nan("")) == "nan");
  CHECK(format_shortest(-INFINITY) == "-inf");
  // Round trip on awkward values (the planted fault, 6 digits, loses the last two).
  for (const double value : {0.1 + 0.2, std::numbers::pi, 1.0 / 3.0, DBL_MIN, DBL_MAX})
    CHECK(std::strtod(format_shortest(value).c_str(), nullptr) == value);
  char six_digits[32];
  std::snprintf(six_digits, sizeof six_digits, "%g", 0.1 + 0.2);
  CHECK(std::strtod(six_digits, nullptr) != 0.1 + 0.2);
}

namespace {

// The tests' tolerance checks accumulate errors from 0 and then CHECK(worst <= tolerance); a NaN
// error (a kernel or a policy gone wrong) must fail that check. Errors of 1e-12 to 3e-10 against
// a tolerance of 1e-9, with a NaN planted at `nan_at` (none when it is past the end).
std::vector<double> errors_with_nan_at(std::size_t nan_at) {
  std::vector<double> errors = {1e-12, 3e-10, 0.0, 2e-11};
  if (nan_at < errors.size()) errors[nan_at] = kNan;
  return errors;
}

double worst_error_by(double (*accumulate)(double, double), const std::vector<double>& errors) {
  double worst = 0.0;
  for (const double error : errors) worst = accumulate(worst, error);
  return worst;
}

double worst_by_std_max(double worst, double error) {
  return std::max(worst, error);
}

}  // namespace

TEST_CASE("worst_of_fails_the_tolerance_check_on_a_nan_among_finite_errors", "[unit]") {
  CHECK(worst_error_by(test::worst_of, errors_with_nan_at(4)) == 3e-10);
  for (std::size_t nan_at = 0; nan_at < 4; ++nan_at) {
    INFO("NaN at " << nan_at);
    const double worst = worst_error_by(test::worst_of, errors_with_nan_at(nan_at));
    CHECK(std::isnan(worst));
    CHECK_FALSE(worst <= 1e-9);
  }
}

TEST_CASE("mutant_std_max_passes_the_tolerance_check_on_a_nan_among_finite_errors", "[unit]") {
  // The planted fault is the accumulation worst_of replaced: std::max(worst, NaN) is worst.
  for (std::size_t nan_at = 0; nan_at < 4; ++nan_at) {
    INFO("NaN at " << nan_at);
    const double worst = worst_error_by(worst_by_std_max, errors_with_nan_at(nan_at));
    CHECK(worst == (nan_at == 1 ? 2e-11 : 3e-10));  // the largest finite error left
    CHECK(worst <= 1e-9);
  }
}

TEST_CASE("format_readable_prints_rounding_noise_as_0_and_keeps_the_rest", "[unit]") {
  // A half turn about y, with what rounding leaves of the other two components.
  const Eigen::Vector3d half_turn(-2.3e-10, -std::numbers::pi, 9.7e-10);
  CHECK(format_readable(half_turn) == "[0, -3.14159, 0]");
  // The noise is 1e-9 (1 + the largest): a pose 1 cm out moved off by 1e-9 m reads as 1 cm out.
  CHECK(format_readable(Eigen::Vector3d(-7.6e-10, 5.6e-11, -0.01)) == "[0, 0, -0.01]");
  CHECK(format_readable(Eigen::Vector3d(1.0, 2.1e-9, -0.0)) == "[1, 2.1e-09, 0]");
  // Below a noise of 0, or of 1e-9 of the largest (as g prints), 1e-12 rad is a value.
  CHECK(format_readable(Eigen::Vector3d(0.0, 0.0, 1e-12), 6, 0.0) == "[0, 0, 1e-12]");
  CHECK(format_readable(Eigen::Vector3d(0.0, 0.0, 1e-12), 6, 1e-21) == "[0, 0, 1e-12]");
  CHECK(format_readable(Eigen::Vector3d(0.1 + 0.2, 1.0 / 3.0, kNan), 3, 1.0) == "[0, 0, nan]");
  CHECK(format_readable(Eigen::Vector3d(0.1 + 0.2, 1.0 / 3.0, 2.0), 3, 0.0) == "[0.3, 0.333, 2]");
  CHECK(std::isnan(largest_magnitude(Eigen::Vector3d(1.0, kNan, 0.0))));
  CHECK(format_digits(-0.0) == "0");
  CHECK(format_digits(INFINITY) == "inf");
  // The planted fault, the same digits with no noise, reads the rounding as values.
  CHECK(format_readable(half_turn, 6, 0.0) == "[-2.3e-10, -3.14159, 9.7e-10]");
}

TEST_CASE("digits_to_tell_apart_shows_the_difference_an_error_names", "[unit]") {
  CHECK(digits_to_tell_apart(1.0, 2.0) == 6);
  CHECK(digits_to_tell_apart(1.0, 1.0 + 1e-9) == 10);
  CHECK(format_digits(1.0, 10) != format_digits(1.0 + 1e-9, 10));
  CHECK(digits_to_tell_apart(0.5, 0.5) == 6);
  CHECK(digits_to_tell_apart(1.0, std::nextafter(1.0, 2.0)) == 17);
}
