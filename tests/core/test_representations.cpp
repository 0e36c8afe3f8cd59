// The four representations: round trips, values worked by hand, and the invariances that
// define them (the full classifier over all groups is in tests/props).
#include <catch2/catch.hpp>

#include "throws.hpp"  // tests/support
#include <numbers>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/props/catch.hpp"
#include "handcentric/props/observation/generators.hpp"
#include "handcentric/props/show.hpp"
#include "mutants.hpp"

using namespace handcentric;

namespace {

// The scale of a scene: round-trip tolerances are 1e-12 relative to it (a translation of
// 1e3 cannot round-trip to 1e-12 absolute in double).
double scale_of(const Scene& scene) {
  double scale = 1.0;
  for (const auto& T : scene.world_T_hand_history) scale = std::max(scale, T.translation().norm());
  for (const auto& T : scene.world_T_hand_chunk) scale = std::max(scale, T.translation().norm());
  return scale;
}

// decode(encode(scene), T_0) = chunk, within 1e-12 relative to the scene's scale.
auto round_trip(std::shared_ptr<const Representation> representation) {
  return [representation] {
    const Scene scene = *props::scene();
    const auto decoded = representation->decode_actions(representation->encode_actions(scene),
                                                        scene.world_T_hand0());
    RC_ASSERT(decoded.size() == scene.world_T_hand_chunk.size());
    for (std::size_t k = 0; k < decoded.size(); ++k) {
      RC_ASSERT(distance(decoded[k], scene.world_T_hand_chunk[k]) <= 1e-12 * scale_of(scene));
    }
  };
}

// encode_actions(g * scene) = encode_actions(scene) for g in `group`.
auto actions_invariant(std::shared_ptr<const Representation> representation, props::Group group) {
  return [representation, group] {
    const Scene scene = *props::scene();
    const RigidTransform g = *props::group_element(group);
    const Eigen::VectorXd before = representation->encode_actions(scene);
    const Eigen::VectorXd after = representation->encode_actions(g * scene);
    RC_ASSERT((after - before).lpNorm<Eigen::Infinity>() <=
              1e-9 * (scale_of(scene) + g.translation().norm()));
  };
}

}  // namespace

TEST_CASE("decode_of_encode_returns_the_chunk_for_every_builtin", "[property]") {
  for (const std::string& name : builtin_representation_names()) {
    props::require_property(
        name + ": decode(encode(scene)) = chunk",
        round_trip(std::shared_ptr<const Representation>(make_representation(name))));
  }
}

TEST_CASE("mutant_encoders_fail_the_round_trip", "[property]") {
  props::require_falsified("forgets R_0^T",
                           round_trip(std::make_shared<test::ForgetsRotationOnTranslation>()));
  props::require_falsified("R_0 for R_0^T",
                           round_trip(std::make_shared<test::UsesR0ForR0Transpose>()));
}

TEST_CASE("hand_centric_actions_are_se3_invariant", "[property]") {
  props::require_property(
      "hand_centric actions under se3",
      actions_invariant(std::make_shared<HandCentricRepresentation>(), props::Group::se3));
}

TEST_CASE("mutant_hand_centric_encoders_are_not_se3_invariant", "[property]") {
  props::require_falsified(
      "forgets R_0^T, se3",
      actions_invariant(std::make_shared<test::ForgetsRotationOnTranslation>(), props::Group::se3));
  props::require_falsified(
      "R_0 for R_0^T, se3",
      actions_invariant(std::make_shared<test::UsesR0ForR0Transpose>(), props::Group::se3));
}

TEST_CASE("relative_actions_are_translation_invariant_but_not_rotation_invariant", "[property]") {
  auto relative = std::make_shared<RelativeRepresentation>();
  props::require_property("relative under translation",
                          actions_invariant(relative, props::Group::translation));
  props::require_falsified("relative under rotation",
                           actions_invariant(relative, props::Group::rotation));
  props::require_falsified(
      "absolute under translation",
      actions_invariant(std::make_shared<AbsoluteRepresentation>(), props::Group::translation));
}

TEST_CASE("encodings_match_values_worked_by_hand", "[unit]") {
  // T_0: rotated 90 deg about z, at (1, 2, 3). T_1: rotated 180 deg about z, at (1, 3, 3).
  constexpr double pi = std::numbers::pi;
  Scene scene;
  scene.world_T_hand_history = {RigidTransform::planar(pi / 2, 1, 2)};
  scene.world_T_hand_chunk = {RigidTransform::planar(pi, 1, 3)};
  scene.world_T_hand_history[0] =
      RigidTransform(Rotation::about_z(pi / 2), Eigen::Vector3d(1, 2, 3));
  scene.world_T_hand_chunk[0] = RigidTransform(Rotation::about_z(pi), Eigen::Vector3d(1, 3, 3));
  scene.hand_points = {Eigen::Vector3d(0.5, 0, 0)};

  using V6 = Eigen::Matrix<double, 6, 1>;
  // absolute: (p_1, r(R_1)) = (1, 3, 3, 0, 0, pi)
  CHECK((AbsoluteRepresentation().encode_actions(scene) - (V6() << 1, 3, 3, 0, 0, pi).finished())
            .norm() < 1e-15);
  // relative: (p_1 - p_0, r(R_0^T R_1)) = (0, 1, 0, 0, 0, pi/2)
  CHECK(
      (RelativeRepresentation().encode_actions(scene) - (V6() << 0, 1, 0, 0, 0, pi / 2).finished())
          .norm() < 1e-15);
  // relative_diff: (p_1 - p_0, r(R_1) - r(R_0)) = (0, 1, 0, 0, 0, pi - pi/2)
  CHECK((RelativeDiffRepresentation().encode_actions(scene) -
         (V6() << 0, 1, 0, 0, 0, pi / 2).finished())
            .norm() < 1e-15);
  // hand_centric: R_0^T (p_1 - p_0) = Rz(-90)(0, 1, 0) = (1, 0, 0); r = (0, 0, pi/2)
  CHECK((HandCentricRepresentation().encode_actions(scene) -
         (V6() << 1, 0, 0, 0, 0, pi / 2).finished())
            .norm() < 1e-15);
  // observations: [T_0 part, eye-in-hand point]
  Eigen::VectorXd world_obs(9), hand_obs(9);
  world_obs << 1, 2, 3, 0, 0, pi / 2, 0.5, 0, 0;
  hand_obs << 0, 0, 0, 0, 0, 0, 0.5, 0, 0;
  CHECK((AbsoluteRepresentation().encode_observation(scene) - world_obs).norm() < 1e-15);
  CHECK((HandCentricRepresentation().encode_observation(scene) - hand_obs).norm() < 1e-15);
}

TEST_CASE("representations_reject_bad_vectors_and_names", "[unit]") {
  const HandCentricRepresentation hand_centric;
  HC_CHECK_THROWS(hand_centric.decode_actions(Eigen::VectorXd::Zero(7), RigidTransform()),
                  InvalidArgument,
                  Catch::Matchers::Contains("length 7") && Catch::Matchers::Contains("6K"));
  Eigen::VectorXd with_nan = Eigen::VectorXd::Zero(6);
  with_nan(3) = std::nan("");
  HC_CHECK_THROWS(hand_centric.decode_actions(with_nan, RigidTransform()), InvalidArgument,
                  Catch::Matchers::Contains("non-finite"));
  HC_CHECK_THROWS(
      make_representation("hand-centric"), InvalidArgument,
      Catch::Matchers::Contains("'hand-centric'") && Catch::Matchers::Contains("hand_centric"));
  CHECK_THROWS_AS(hand_centric.encode_actions(Scene{}), InvalidScene);
}
