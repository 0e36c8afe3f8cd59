// A representation of our own: translation in the hand frame at the time of control, but the
// rotation as an absolute rotation vector ("half hand-centric"). We want to know which global
// transforms leave its actions invariant, before we train on it.
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>

#include <handcentric/core/representation.hpp>
#include <handcentric/core/so3.hpp>
#include <handcentric/props/catch.hpp>
#include <handcentric/props/observation/generators.hpp>
#include <handcentric/props/show.hpp>

namespace {

using handcentric::RigidTransform;
using handcentric::Scene;

class HalfHandCentric final : public handcentric::Representation {
 public:
  std::string name() const override { return "half_hand_centric"; }
  Eigen::VectorXd encode_actions(const Scene& scene) const override {
    scene.validate();
    const RigidTransform& world_T_hand0 = scene.world_T_hand0();
    Eigen::VectorXd a(6 * scene.chunk_length());
    for (int k = 0; k < scene.chunk_length(); ++k) {
      const RigidTransform& world_T_handk = scene.world_T_hand_chunk[static_cast<std::size_t>(k)];
      a.segment<3>(6 * k) = world_T_hand0.rotation().matrix().transpose() *
                            (world_T_handk.translation() - world_T_hand0.translation());
      a.segment<3>(6 * k + 3) = world_T_handk.rotation().log();
    }
    return a;
  }
  Eigen::VectorXd encode_observation(const Scene& scene) const override {
    Eigen::VectorXd o(3 * static_cast<Eigen::Index>(scene.hand_points.size()));
    for (std::size_t i = 0; i < scene.hand_points.size(); ++i)
      o.segment<3>(3 * static_cast<Eigen::Index>(i)) = scene.hand_points[i];
    return o;
  }
  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd& a,
                                             const RigidTransform& world_T_hand0) const override {
    std::vector<RigidTransform> chunk;
    for (Eigen::Index k = 0; 6 * k < a.size(); ++k) {
      chunk.push_back(RigidTransform::unchecked(
          handcentric::so3::exp(a.segment<3>(6 * k + 3)),
          world_T_hand0.translation() + world_T_hand0.rotation().matrix() * a.segment<3>(6 * k)));
    }
    return chunk;
  }
};

auto actions_invariant_under(handcentric::props::Group group) {
  return [group] {
    const Scene scene = *handcentric::props::scene();
    const RigidTransform g = *handcentric::props::group_element(group);
    const HalfHandCentric representation;
    const Eigen::VectorXd before = representation.encode_actions(scene);
    const Eigen::VectorXd after = representation.encode_actions(g * scene);
    RC_ASSERT((after - before).lpNorm<Eigen::Infinity>() <= 1e-9 * (1.0 + g.translation().norm()));
  };
}

}  // namespace

TEST_CASE("half_hand_centric_actions_are_translation_invariant", "[property]") {
  handcentric::props::require_property(
      "translation", actions_invariant_under(handcentric::props::Group::translation));
}

TEST_CASE("half_hand_centric_actions_are_not_rotation_invariant", "[property]") {
  // the absolute rotation vector breaks it: RapidCheck must find (and shrink) a witness
  const auto outcome = handcentric::props::require_falsified(
      "rotation", actions_invariant_under(handcentric::props::Group::rotation));
  CHECK_FALSE(outcome.counterexample.empty());
}

TEST_CASE("half_hand_centric_observation_is_eye_in_hand_only", "[unit]") {
  Scene scene;
  scene.world_T_hand_history = {RigidTransform()};
  scene.world_T_hand_chunk = {RigidTransform()};
  scene.hand_points = {Eigen::Vector3d(1, 2, 3)};
  CHECK(HalfHandCentric().encode_observation(scene) == Eigen::Vector3d(1, 2, 3));
}
