// SE(3): composition, inverse, inverse-compose, exp/log, planar SE(2), validation.
#include <catch2/catch.hpp>

#include "throws.hpp"  // tests/support
#include <numbers>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/props/catch.hpp"
#include "handcentric/props/observation/generators.hpp"
#include "handcentric/props/show.hpp"

using namespace handcentric;

namespace {

rc::Gen<RigidTransform> any_transform() {
  return props::group_element(props::Group::se3);
}

// A fault: inverse_compose that forgets the rotation on the translation.
RigidTransform broken_inverse_compose(const RigidTransform& a, const RigidTransform& b) {
  return RigidTransform::unchecked(a.rotation().matrix().transpose() * b.rotation().matrix(),
                                   b.translation() - a.translation());
}
RigidTransform real_inverse_compose(const RigidTransform& a, const RigidTransform& b) {
  return a.inverse_compose(b);
}

auto inverse_compose_matches_definition(RigidTransform (*fn)(const RigidTransform&,
                                                             const RigidTransform&)) {
  return [fn] {
    const RigidTransform a = *any_transform();
    const RigidTransform b = *any_transform();
    const double scale = 1.0 + a.translation().norm() + b.translation().norm();
    RC_ASSERT(distance(fn(a, b), a.inverse() * b) <= 1e-12 * scale);
  };
}

}  // namespace

TEST_CASE("inverse_compose_equals_inverse_then_compose", "[property]") {
  props::require_property("a.inverse_compose(b) = a^-1 b",
                          inverse_compose_matches_definition(real_inverse_compose));
}

TEST_CASE("mutant_inverse_compose_without_rotation_is_caught", "[property]") {
  props::require_falsified("broken inverse_compose",
                           inverse_compose_matches_definition(broken_inverse_compose));
}

TEST_CASE("composition_is_associative_and_inverse_cancels", "[property]") {
  props::require_property("(ab)c = a(bc), a a^-1 = I, and (ab)x = a(bx)", [] {
    const RigidTransform a = *any_transform(), b = *any_transform(), c = *any_transform();
    const Eigen::Vector3d x = *props::translation(10.0);
    const double scale =
        1.0 + a.translation().norm() + b.translation().norm() + c.translation().norm();
    RC_ASSERT(distance((a * b) * c, a * (b * c)) <= 1e-12 * scale);
    RC_ASSERT(distance(a * a.inverse(), RigidTransform()) <= 1e-12 * scale);
    RC_ASSERT(((a * b) * x - a * (b * x)).norm() <= 1e-12 * (scale + x.norm()));
    // a homogeneous-matrix cross-check
    RC_ASSERT(((a * b).matrix() - a.matrix() * b.matrix()).norm() <= 1e-12 * scale);
  });
}

TEST_CASE("se3_exp_of_log_is_identity", "[property]") {
  props::require_property("exp(log(T)) = T", [] {
    const RigidTransform T = *any_transform();
    RC_ASSERT(distance(RigidTransform::exp(T.log()), T) <= 1e-11 * (1.0 + T.translation().norm()));
  });
}

TEST_CASE("mutant_se3_log_without_v_inverse_is_caught", "[property]") {
  // a log that takes rho = p (forgets V^{-1}) is only right for pure translations
  props::require_falsified("exp(rho = p, omega) = T", [] {
    const RigidTransform T = *any_transform();
    Twist wrong;
    wrong << T.translation(), T.rotation().log();
    RC_ASSERT(distance(RigidTransform::exp(wrong), T) <= 1e-11 * (1.0 + T.translation().norm()));
  });
}

TEST_CASE("planar_transforms_are_rotations_about_z", "[unit]") {
  const RigidTransform T = RigidTransform::planar(std::numbers::pi / 2, 1.0, 2.0);
  CHECK((T * Eigen::Vector3d(1, 0, 5) - Eigen::Vector3d(1, 3, 5)).norm() < 1e-15);
  CHECK((T.rotation().log() - Eigen::Vector3d(0, 0, std::numbers::pi / 2)).norm() < 1e-15);
}

TEST_CASE("transform_constructors_reject_bad_input", "[unit]") {
  HC_CHECK_THROWS(RigidTransform(Rotation(), Eigen::Vector3d(0, std::nan(""), 0)), InvalidTransform,
                  Catch::Matchers::Contains("[0, nan, 0]"));
  Eigen::Matrix4d bad_row = Eigen::Matrix4d::Identity();
  bad_row(3, 0) = 0.5;
  HC_CHECK_THROWS(RigidTransform::from_matrix(bad_row), InvalidTransform,
                  Catch::Matchers::Contains("[0, 0, 0, 1]") && Catch::Matchers::Contains("0.5"));
  Eigen::Matrix4d reflection = Eigen::Matrix4d::Identity();
  reflection(2, 2) = -1;
  CHECK_THROWS_AS(RigidTransform::from_matrix(reflection), InvalidRotation);
  Twist nan_twist = Twist::Zero();
  nan_twist(4) = std::numeric_limits<double>::infinity();
  CHECK_THROWS_AS(RigidTransform::exp(nan_twist), InvalidTransform);
  CHECK_THROWS_AS(RigidTransform::planar(0, std::nan(""), 0), InvalidTransform);
}
