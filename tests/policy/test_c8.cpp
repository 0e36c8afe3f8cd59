// The C8-symmetrized flow (analogue of [7]): the group action on absolute vectors agrees with
// g * scene, its differential matches finite differences, and the frame-averaged field is exactly
// C8-equivariant but not translation-equivariant.
#include <catch2/catch.hpp>

#include "fixtures.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/policy/c8_action.hpp"
#include "handcentric/policy/c8_flow.hpp"
#include "handcentric/policy/trainer.hpp"
#include "handcentric/props/catch.hpp"
#include "handcentric/props/observation/generators.hpp"
#include "worst_error.hpp"  // tests/support

using namespace handcentric;
using namespace handcentric::policy;

namespace {

Scene random_c8_scene(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  return random_scene(rng, 2, 4, 2, 1, 2.0);
}

// encode(g scene) = g encode(scene) for g in C8, on actions and observations; `hand_points`
// is the layout the action assumes (2 is right).
auto action_matches_scene_transform(int hand_points) {
  return [hand_points] {
    const Scene scene = random_c8_scene(*rc::gen::arbitrary<std::uint64_t>());
    const int k = *rc::gen::inRange(1, 8);
    const RigidTransform g = RigidTransform::planar(k * std::numbers::pi / 4.0, 0.0, 0.0);
    const AbsoluteRepresentation absolute;
    const Eigen::Matrix3d R = c8::rotation(k);
    RC_ASSERT(
        (absolute.encode_actions(g * scene) - c8::act_on_actions(R, absolute.encode_actions(scene)))
            .cwiseAbs()
            .maxCoeff<Eigen::PropagateNaN>() < 1e-9);
    RC_ASSERT((absolute.encode_observation(g * scene) -
               c8::act_on_observation(R, absolute.encode_observation(scene), 2, hand_points))
                  .cwiseAbs()
                  .maxCoeff<Eigen::PropagateNaN>() < 1e-9);
  };
}

}  // namespace

TEST_CASE("c8_action_on_absolute_vectors_is_the_scene_transform", "[property]") {
  props::require_property("encode(g scene) = g encode(scene)", action_matches_scene_transform(2));
  // Planted fault: eye-in-hand points rotated as if they were world points.
  props::require_falsified("hand points treated as world points",
                           action_matches_scene_transform(0));
}

TEST_CASE("c8_rotations_compose_exactly", "[unit]") {
  for (int j = 0; j < 8; ++j) {
    for (int k = 0; k < 8; ++k) {
      CHECK((c8::rotation(j) * c8::rotation(k) - c8::rotation(j + k))
                .cwiseAbs()
                .maxCoeff<Eigen::PropagateNaN>() < 1e-15);
    }
  }
}

TEST_CASE("c8_velocity_push_forward_matches_finite_differences", "[unit]") {
  std::mt19937_64 rng(12);
  double worst = 0.0, worst_without_jacobians = 0.0;
  for (int trial = 0; trial < 50; ++trial) {
    Eigen::VectorXd a(12), v(12);
    for (int i = 0; i < 12; ++i) {
      a[i] = 2.0 * uniform01(rng) - 1.0;
      v[i] = 2.0 * uniform01(rng) - 1.0;
    }
    a.segment<3>(3) *= 2.5;  // a rotation vector of angle up to ~2.5 * sqrt(3) > pi/2
    const Eigen::Matrix3d R = c8::rotation(1 + trial % 7);
    const double h = 1e-6;
    const Eigen::VectorXd numeric =
        (c8::act_on_actions(R, a + h * v) - c8::act_on_actions(R, a - h * v)) / (2 * h);
    if (a.segment<3>(3).norm() > 3.0 || a.segment<3>(9).norm() > 3.0)
      continue;  // keep away from |r| = pi
    worst = test::worst_of(
        worst, (numeric - c8::push_velocity(R, a, v)).cwiseAbs().maxCoeff<Eigen::PropagateNaN>());
    // Planted fault: rotating the rotation-vector velocity like a translation.
    Eigen::VectorXd naive = v;
    for (int i = 0; i < 12; i += 3) naive.segment<3>(i) = R * v.segment<3>(i);
    worst_without_jacobians = test::worst_of(
        worst_without_jacobians, (numeric - naive).cwiseAbs().maxCoeff<Eigen::PropagateNaN>());
  }
  CHECK(worst < 1e-6);
  CHECK(worst_without_jacobians > 1e-2);
}

namespace {

std::shared_ptr<const LearnedPolicy> trained_c8() {
  std::vector<Scene> scenes;
  for (std::uint64_t s = 0; s < 64; ++s) scenes.push_back(random_c8_scene(100 + s));
  return std::make_shared<LearnedPolicy>(
      train_policy(test::small_config(HeadKind::c8flow, "absolute", 100), scenes, 5));
}

// F(g x, g o) = g_* F(x, o) at x, o from a random scene (rotation vectors inside the ball).
auto field_equivariant(std::shared_ptr<const LearnedPolicy> policy, props::Group group,
                       bool symmetrized) {
  return [policy, group, symmetrized] {
    const Scene scene = random_c8_scene(*rc::gen::arbitrary<std::uint64_t>());
    const double t = *rc::gen::inRange(0, 10) / 10.0;
    const AbsoluteRepresentation absolute;
    const Eigen::VectorXd x = absolute.encode_actions(scene),
                          o = absolute.encode_observation(scene);
    const RigidTransform g = *props::group_element(group);
    const Eigen::VectorXd x_moved = absolute.encode_actions(g * scene);
    const Eigen::VectorXd o_moved = absolute.encode_observation(g * scene);
    const Eigen::VectorXd F = c8_velocity(policy->head(), x, o, t, symmetrized);
    const Eigen::VectorXd F_moved = c8_velocity(policy->head(), x_moved, o_moved, t, symmetrized);
    // g_* for a rigid g = [R | p]: the translation part of a velocity only rotates.
    const Eigen::VectorXd expected = c8::push_velocity(g.rotation().matrix(), x, F);
    RC_ASSERT((F_moved - expected).cwiseAbs().maxCoeff<Eigen::PropagateNaN>() <=
              1e-4 * (1.0 + F.cwiseAbs().maxCoeff<Eigen::PropagateNaN>()));
  };
}

}  // namespace

TEST_CASE("c8flow_field_is_c8_equivariant_but_not_translation_equivariant", "[property]") {
  const auto policy = trained_c8();
  props::require_property("F(g x, g o) = g_* F(x, o), g in C8",
                          field_equivariant(policy, props::Group::c8, true));
  props::require_falsified("F under translations",
                           field_equivariant(policy, props::Group::translation, true));
  // Planted fault: the network's field without the frame average.
  props::require_falsified("f without averaging, g in C8",
                           field_equivariant(policy, props::Group::c8, false));
}
