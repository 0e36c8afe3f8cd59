// The in-distribution test: energy distance, its permutation p-value, and what separates
// ActionFlow's field (rotation-invariant in distribution, eq. 29 with eps ~ N(0, I)) from one
// that is invariant outright or not at all.
#include <catch2/catch.hpp>
#include <memory>
#include <random>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/props/distribution.hpp"
#include "mutants.hpp"

using namespace handcentric;
using props::Component;
using props::Group;

namespace {

Eigen::MatrixXd normal_sample(int rows, int cols, std::uint64_t seed, double shift) {
  std::mt19937_64 rng(seed);
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = standard_normal(rng);
  m.col(0).array() += shift;
  return m;
}

props::CheckOptions fast() {
  props::CheckOptions options = props::eye_in_hand_options();
  options.cases = 10;
  return options;
}

}  // namespace

TEST_CASE("energy_distance_is_zero_for_the_same_sample_and_grows_with_a_shift", "[unit]") {
  const Eigen::MatrixXd x = normal_sample(30, 4, 1, 0.0);
  CHECK(std::abs(props::energy_distance(x, x)) < 1e-12);
  const double small = props::energy_distance(x, normal_sample(30, 4, 2, 0.5));
  const double large = props::energy_distance(x, normal_sample(30, 4, 2, 3.0));
  CHECK(large > small);
  CHECK_THROWS_AS(props::energy_distance(x, Eigen::MatrixXd(3, 5)), InvalidArgument);
  CHECK_THROWS_AS(props::energy_test(x, x, 0, 1), InvalidArgument);
}

TEST_CASE("energy_test_rejects_a_shift_and_keeps_two_samples_of_one_law", "[unit]") {
  const Eigen::MatrixXd x = normal_sample(32, 6, 11, 0.0);
  const props::TwoSampleResult shifted = props::energy_test(x, normal_sample(32, 6, 12, 2.0), 999, 5);
  CHECK(shifted.p_value <= 0.002);
  const props::TwoSampleResult same = props::energy_test(x, normal_sample(32, 6, 13, 0.0), 999, 5);
  CHECK(same.p_value > 0.05);
  // Deterministic given the seed; the sequential stop decides like the full test.
  CHECK(props::energy_test(x, normal_sample(32, 6, 13, 0.0), 999, 5).p_value == same.p_value);
  CHECK(props::energy_test(x, normal_sample(32, 6, 13, 0.0), 999, 5, 0.01).p_value >= 0.01);
  CHECK(props::energy_test(x, normal_sample(32, 6, 12, 2.0), 999, 5, 0.01).p_value == shifted.p_value);
  CHECK(props::permutations_for(0.001) >= 1999);
}

TEST_CASE("actionflow_target_is_rotation_invariant_in_distribution_but_not_translation_invariant", "[property]") {
  const auto actionflow = std::make_shared<ActionFlowTarget>();
  for (Group group : {Group::rotation, Group::c8}) {
    const props::Verdict verdict = props::check_distribution_invariance(actionflow, Component::flow_target, group, fast());
    INFO(props::to_string(group) << ": min p " << verdict.min_p_value);
    CHECK(verdict.invariant);
    CHECK(verdict.mode == props::Mode::distribution);
  }
  for (Group group : {Group::translation, Group::se2, Group::se3}) {
    const props::Verdict verdict = props::check_distribution_invariance(actionflow, Component::flow_target, group, fast());
    INFO(props::to_string(group));
    CHECK_FALSE(verdict.invariant);
    REQUIRE(verdict.witness.has_value());
    CHECK(verdict.witness->p_value < verdict.witness->tolerance);
  }
}

TEST_CASE("mutant_biased_noise_breaks_rotation_invariance_in_distribution", "[property]") {
  const auto mutant = std::make_shared<test::BiasedNoiseActionFlow>();
  const props::Verdict verdict = props::check_distribution_invariance(mutant, Component::flow_target, Group::rotation, fast());
  CHECK_FALSE(verdict.invariant);
  REQUIRE(verdict.witness.has_value());
  CHECK(verdict.witness->p_value < verdict.witness->tolerance);
}

TEST_CASE("a_pointwise_invariant_flow_is_invariant_in_distribution", "[property]") {
  const auto hand_flow = std::make_shared<RectifiedFlow>(std::make_shared<HandCentricRepresentation>());
  for (Component component : {Component::flow_input, Component::flow_target}) {
    const props::Verdict verdict = props::check_distribution_invariance(hand_flow, component, Group::se3, fast());
    CHECK(verdict.invariant);
    CHECK(verdict.min_p_value == 1.0);
  }
  CHECK_THROWS_AS(props::check_distribution_invariance(hand_flow, Component::actions, Group::se3, fast()),
                  InvalidArgument);
}
