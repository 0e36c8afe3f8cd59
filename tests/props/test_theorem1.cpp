// Theorem 1 and Lemmas 1-2 as properties: for ANY network (untrained, random weights, several
// sizes and seeds) the outer policy on hand_centric with eye-in-hand observations is
// SE(3)-equivariant, a(g o) = g a(o) (eq. 4). On absolute, relative or relative_diff, or with a
// world-frame point in the observation (a third-person view), a witness is found and rechecked.
#include <catch2/catch.hpp>
#include <memory>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/props/checks/check.hpp"
#include "handcentric/props/random_network.hpp"
#include "mutants.hpp"

using namespace handcentric;
using props::Group;

namespace {

constexpr int kHistory = 2, kChunk = 4, kHandPoints = 2;

// Fixed sizes, so that one network reads every observation: H = 2, K = 4, 2 eye-in-hand points.
props::CheckOptions policy_options(int world_points, int cases = 150) {
  props::CheckOptions options;
  options.cases = cases;
  options.noise_seed = 99;
  options.shape.min_history = options.shape.max_history = kHistory;
  options.shape.min_chunk = options.shape.max_chunk = kChunk;
  options.shape.min_hand_points = options.shape.max_hand_points = kHandPoints;
  options.shape.min_world_points = options.shape.max_world_points = world_points;
  return options;
}

int observation_dimension(int world_points) {
  return 6 * (kHistory + 1) + 3 * kHandPoints + 3 * world_points;
}

struct NetworkSize {
  std::vector<int> hidden;
  std::uint64_t seed;
};

const std::vector<NetworkSize> kNetworks = {{{8}, 1}, {{32, 32}, 2}, {{64, 16, 64}, 3}, {{128}, 4}};

// The witness is recomputed from its scene and g, and is above tolerance.
void require_checked_witness(const ChunkPolicy& policy, const props::Verdict& verdict,
                             std::uint64_t noise_seed) {
  REQUIRE_FALSE(verdict.invariant);
  REQUIRE(verdict.witness.has_value());
  CHECK(props::recompute_equivariance_error(policy, *verdict.witness, noise_seed) ==
        verdict.witness->error);
  CHECK(verdict.witness->error > verdict.witness->tolerance);
}

}  // namespace

TEST_CASE("hand_centric_outer_policy_of_any_random_network_is_se3_equivariant", "[property]") {
  const auto hand_centric = std::make_shared<HandCentricRepresentation>();
  for (const NetworkSize& size : kNetworks) {
    const props::RandomOuterPolicy policy(hand_centric, observation_dimension(0), kChunk,
                                          size.hidden, size.seed);
    for (Group group : props::all_groups()) {
      const props::Verdict verdict = props::check_equivariance(policy, group, policy_options(0));
      INFO("network seed " << size.seed << ", " << props::to_string(group) << ", max error "
                           << verdict.max_error);
      CHECK(verdict.invariant);
      CHECK(verdict.max_error < 1e-9 * 2e3);  // tolerance 1e-9 (1 + L), L <= ~1.1e3
    }
  }
}

TEST_CASE("lemma_2_a_random_inner_network_on_invariant_inputs_gives_invariant_actions",
          "[property]") {
  // Lemma 2: ^R pi(^R o, o_v) is invariant when its inputs are (eq. 9 and eye-in-hand points).
  // Lemma 1 then turns that invariance into the equivariance checked above (eq. 8).
  const props::RandomMlp network(observation_dimension(0) + 6 * kChunk, {32, 32}, 6 * kChunk, 11);
  auto inner_policy =
      [&network](std::shared_ptr<const Representation> representation) -> props::SceneFunction {
    return [&network, representation](const Scene& scene) -> Eigen::VectorXd {
      Eigen::VectorXd input(network.inputs());
      input << representation->encode_observation(scene), props::fixed_noise(6 * kChunk, 99);
      return network(input);
    };
  };
  const auto hand = inner_policy(std::make_shared<HandCentricRepresentation>());
  CHECK(props::check_invariance(hand, props::Component::actions, Group::se3, policy_options(0))
            .invariant);
  // Planted fault: world-frame proprioception as the input.
  const auto world = inner_policy(std::make_shared<AbsoluteRepresentation>());
  const props::Verdict verdict =
      props::check_invariance(world, props::Component::actions, Group::se3, policy_options(0));
  REQUIRE_FALSE(verdict.invariant);
  REQUIRE(verdict.witness.has_value());
  CHECK(props::recompute_error(world, *verdict.witness) == verdict.witness->error);
}

TEST_CASE("outer_policies_on_absolute_relative_and_relative_diff_yield_checked_witnesses",
          "[property]") {
  for (const char* name : {"absolute", "relative", "relative_diff"}) {
    const std::shared_ptr<const Representation> representation = make_representation(name);
    for (const NetworkSize& size : {kNetworks[0], kNetworks[2]}) {
      const props::RandomOuterPolicy policy(representation, observation_dimension(0), kChunk,
                                            size.hidden, size.seed);
      INFO(name << ", network seed " << size.seed);
      require_checked_witness(policy,
                              props::check_equivariance(policy, Group::se3, policy_options(0)), 99);
    }
  }
}

TEST_CASE("a_third_person_view_copied_raw_breaks_theorem_1_and_one_in_the_hand_frame_does_not",
          "[property]") {
  // One world-frame point copied raw into the observation: Theorem 1's eye-in-hand assumption is
  // violated, and the outer policy is no longer equivariant.
  const props::RandomOuterPolicy raw(std::make_shared<test::RawWorldPoints>(),
                                     observation_dimension(1), kChunk, {32, 32}, 7);
  for (Group group : {Group::translation, Group::rotation, Group::se3}) {
    INFO(props::to_string(group));
    require_checked_witness(raw, props::check_equivariance(raw, group, policy_options(1)), 99);
  }
  // hand_centric takes the point into the hand frame (T_0^{-1} q): equivariant again.
  const props::RandomOuterPolicy hand(std::make_shared<HandCentricRepresentation>(),
                                      observation_dimension(1), kChunk, {32, 32}, 7);
  CHECK(props::check_equivariance(hand, Group::se3, policy_options(1)).invariant);
}

TEST_CASE("mutant_decoder_that_forgets_R0_is_not_equivariant", "[property]") {
  const props::RandomOuterPolicy policy(std::make_shared<test::DecoderForgetsR0>(),
                                        observation_dimension(0), kChunk, {32}, 5);
  require_checked_witness(
      policy, props::check_equivariance(policy, Group::rotation, policy_options(0)), 99);
  // ... while translations alone cannot see it (R_0 is untouched by a translation).
  CHECK(props::check_equivariance(policy, Group::translation, policy_options(0)).invariant);
}

TEST_CASE("random_networks_are_seeded_and_check_their_sizes", "[unit]") {
  const props::RandomMlp a(5, {7}, 3, 42), b(5, {7}, 3, 42), c(5, {7}, 3, 43);
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(5, -1.0, 1.0);
  CHECK(a(x) == b(x));
  CHECK(a(x) != c(x));
  CHECK_THROWS_WITH(a(Eigen::VectorXd::Zero(4)),
                    Catch::Matchers::Contains("expects 5 inputs, got 4"));
  CHECK_THROWS_AS(props::RandomMlp(0, {7}, 3, 1), InvalidArgument);
  CHECK_THROWS_AS(props::RandomOuterPolicy(nullptr, 3, 2, {4}, 1), InvalidArgument);
  const props::RandomOuterPolicy policy(std::make_shared<HandCentricRepresentation>(), 6, 2, {4},
                                        1);
  Scene scene;
  scene.world_T_hand_history = {RigidTransform::identity()};
  CHECK(policy.act(scene, 3).size() == 2);
  scene.hand_points = {Eigen::Vector3d::Zero()};  // 9 numbers, not 6
  CHECK_THROWS_WITH(policy.act(scene, 3), Catch::Matchers::Contains("encodes to 9"));
}
