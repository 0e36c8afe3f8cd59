// The in-distribution test: energy distance, its permutation p-value, and what separates
// ActionFlow's field (rotation-invariant in distribution, eq. 29 with eps ~ N(0, I)) from one
// that is invariant outright or not at all.
#include <catch2/catch.hpp>
#include <Eigen/Geometry>
#include <functional>
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

props::CheckOptions fast_check() {
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
  const props::TwoSampleResult shifted =
      props::energy_test(x, normal_sample(32, 6, 12, 2.0), 999, 5);
  CHECK(shifted.p_value <= 0.002);
  const props::TwoSampleResult same = props::energy_test(x, normal_sample(32, 6, 13, 0.0), 999, 5);
  CHECK(same.p_value > 0.05);
  // Deterministic given the seed; the sequential stop decides like the full test.
  CHECK(props::energy_test(x, normal_sample(32, 6, 13, 0.0), 999, 5).p_value == same.p_value);
  CHECK(props::energy_test(x, normal_sample(32, 6, 13, 0.0), 999, 5, 0.01).p_value >= 0.01);
  CHECK(props::energy_test(x, normal_sample(32, 6, 12, 2.0), 999, 5, 0.01).p_value ==
        shifted.p_value);
  CHECK(props::permutations_for(0.001) >= 1999);
}

TEST_CASE("actionflow_target_is_rotation_invariant_in_distribution_but_not_translation_invariant",
          "[property]") {
  const auto actionflow = std::make_shared<ActionFlowTarget>();
  for (Group group : {Group::rotation, Group::c8}) {
    const props::Verdict verdict = props::check_distribution_invariance(
        actionflow, Component::flow_target, group, fast_check());
    INFO(props::to_string(group) << ": min p " << verdict.min_p_value);
    CHECK(verdict.invariant);
    CHECK(verdict.mode == props::Mode::distribution);
  }
  for (Group group : {Group::translation, Group::se2, Group::se3}) {
    const props::Verdict verdict = props::check_distribution_invariance(
        actionflow, Component::flow_target, group, fast_check());
    INFO(props::to_string(group));
    CHECK_FALSE(verdict.invariant);
    CHECK(verdict.method == props::Method::exact_gaussian);
    REQUIRE(verdict.witness.has_value());
    CHECK(verdict.witness->error > verdict.witness->tolerance);
    CHECK_THAT(verdict.witness->detail, Catch::Matchers::Contains("means differ"));
  }
}

TEST_CASE("mutant_biased_noise_breaks_rotation_invariance_in_distribution", "[property]") {
  const auto mutant = std::make_shared<test::BiasedNoiseActionFlow>();
  const props::Verdict verdict = props::check_distribution_invariance(
      mutant, Component::flow_target, Group::rotation, fast_check());
  CHECK_FALSE(verdict.invariant);
  CHECK(verdict.method == props::Method::exact_gaussian);
  REQUIRE(verdict.witness.has_value());
  CHECK(verdict.witness->error > verdict.witness->tolerance);
}

TEST_CASE("a_pointwise_invariant_flow_is_invariant_in_distribution", "[property]") {
  const auto hand_flow =
      std::make_shared<RectifiedFlow>(std::make_shared<HandCentricRepresentation>());
  for (Component component : {Component::flow_input, Component::flow_target}) {
    const props::Verdict verdict =
        props::check_distribution_invariance(hand_flow, component, Group::se3, fast_check());
    CHECK(verdict.invariant);
    CHECK(verdict.method == props::Method::exact_gaussian);
    CHECK_FALSE(verdict.detectable_shift.has_value());
  }
  CHECK_THROWS_AS(
      props::check_distribution_invariance(hand_flow, Component::actions, Group::se3, fast_check()),
      InvalidArgument);
}

namespace {

// Whether a law comparison tells the world-delta mode's flow target of s from that of g * s
// (a rotation, so the mean a moves): the real comparison must, one that ignores the mean
// (the planted fault) cannot, the covariance being I on both sides.
using Comparison =
    std::function<bool(const props::GaussianLaw&, const props::GaussianLaw&, double)>;
bool tells_delta_mode_apart(const Comparison& different) {
  const auto flow = std::make_shared<RectifiedFlow>(std::make_shared<test::WorldDelta>());
  std::mt19937_64 rng(3);
  const Scene scene = random_scene(rng, 1, 4, 0, 0, 10.0);
  const Scene moved = RigidTransform(Rotation::about_z(0.7), Eigen::Vector3d::Zero()) * scene;
  auto law = [&](const Scene& s) {
    const auto f = [&](const Eigen::VectorXd& eps) { return (*flow)(s, eps, 0.5).target; };
    return *props::affine_law(f, flow->noise_dimension(s), 1e-9, 1);
  };
  return different(law(scene), law(moved), 1e-8);
}

}  // namespace

TEST_CASE("exact_laws_tell_a_moved_mean_apart_and_a_mean_blind_comparison_does_not", "[unit]") {
  const Comparison real = [](const props::GaussianLaw& a, const props::GaussianLaw& b,
                             double tolerance) {
    const props::LawDifference d = props::law_difference(a, b);
    return d.mean > tolerance || d.covariance > tolerance * d.covariance_scale;
  };
  const Comparison mean_blind = [](const props::GaussianLaw& a, const props::GaussianLaw& b,
                                   double tolerance) {
    const props::LawDifference d = props::law_difference(a, b);
    return d.covariance > tolerance * d.covariance_scale;
  };
  CHECK(tells_delta_mode_apart(real));
  CHECK_FALSE(tells_delta_mode_apart(mean_blind));
}

TEST_CASE("affine_law_reads_mean_and_noise_map_and_refuses_a_curved_map", "[unit]") {
  const Eigen::Matrix<double, 3, 2> J =
      (Eigen::Matrix<double, 3, 2>() << 1, 2, 3, 4, 5, 6).finished();
  const Eigen::Vector3d b(7, 8, 9);
  const auto affine = [&](const Eigen::VectorXd& eps) -> Eigen::VectorXd { return b + J * eps; };
  const auto law = props::affine_law(affine, 2, 1e-12, 5);
  REQUIRE(law.has_value());
  CHECK((law->mean - b).norm() == 0.0);
  CHECK((law->noise_map - J).norm() == 0.0);
  const auto curved = [&](const Eigen::VectorXd& eps) -> Eigen::VectorXd {
    return b + J * eps.array().cube().matrix();
  };
  CHECK_FALSE(props::affine_law(curved, 2, 1e-9, 5).has_value());
  // Equal laws from different noise maps: J and J Q for an orthogonal Q give one covariance.
  props::GaussianLaw rotated = *law;
  rotated.noise_map = J * Eigen::Rotation2Dd(0.3).toRotationMatrix();
  CHECK(props::law_difference(*law, rotated).covariance < 1e-12);
  CHECK(props::law_difference(*law, rotated).mean == 0.0);
  props::GaussianLaw stretched = *law;
  stretched.noise_map *= 2.0;
  CHECK(props::law_difference(*law, stretched).covariance > 1.0);
}

TEST_CASE("the_world_delta_mode_is_never_called_invariant_in_distribution_under_rotations",
          "[property]") {
  // The false "yes" an energy test gave on about one seed in four: now an exact answer.
  const auto delta = std::make_shared<RectifiedFlow>(std::make_shared<test::WorldDelta>());
  for (std::uint64_t seed = 1; seed <= 50; ++seed) {
    props::CheckOptions options = fast_check();
    options.seed = seed;
    for (Group group : {Group::rotation, Group::se2, Group::se3, Group::c8}) {
      const props::Verdict verdict =
          props::check_distribution_invariance(delta, Component::flow_target, group, options);
      INFO("seed " << seed << ", " << props::to_string(group));
      CHECK_FALSE(verdict.invariant);
      CHECK(verdict.method == props::Method::exact_gaussian);
    }
    CHECK(props::check_distribution_invariance(delta, Component::flow_target, Group::translation,
                                               options)
              .invariant);
  }
}

TEST_CASE("a_flow_not_affine_in_the_noise_falls_back_to_the_energy_test_and_says_what_it_can_miss",
          "[property]") {
  const auto cubed =
      std::make_shared<test::CubedNoiseFlow>(std::make_shared<HandCentricRepresentation>());
  const props::Verdict same =
      props::check_distribution_invariance(cubed, Component::flow_target, Group::se3, fast_check());
  CHECK(same.invariant);
  CHECK(same.method == props::Method::energy_test);
  REQUIRE(same.detectable_shift.has_value());
  CHECK(*same.detectable_shift > 0.0);
  const auto absolute =
      std::make_shared<test::CubedNoiseFlow>(std::make_shared<AbsoluteRepresentation>());
  const props::Verdict moved = props::check_distribution_invariance(
      absolute, Component::flow_target, Group::translation, fast_check());
  CHECK_FALSE(moved.invariant);
  CHECK(moved.method == props::Method::energy_test);
  REQUIRE(moved.witness.has_value());
  CHECK(moved.witness->p_value < moved.witness->tolerance);
}

TEST_CASE("the_energy_tests_detectable_shift_is_a_measurement", "[unit]") {
  // At the measured shift the test rejects in ~90% of independent repetitions; at a third of it,
  // far less often. A made-up figure would not pass both.
  const double shift = props::energy_test_detectable_shift(4, 32, 0.01);
  CHECK(shift > 0.1);
  CHECK(shift < 10.0);
  auto power = [](double s) {
    std::mt19937_64 rng(777);
    int rejected = 0;
    for (int r = 0; r < 60; ++r) {
      Eigen::MatrixXd x(32, 4), y(32, 4);
      for (Eigen::Index i = 0; i < x.size(); ++i) x.data()[i] = standard_normal(rng);
      for (Eigen::Index i = 0; i < y.size(); ++i) y.data()[i] = standard_normal(rng);
      y.col(0).array() += s;
      if (props::energy_test(x, y, props::permutations_for(0.01), rng(), 0.01).p_value < 0.01)
        ++rejected;
    }
    return rejected / 60.0;
  };
  CHECK(power(shift) >= 0.75);
  CHECK(power(shift / 3.0) < 0.5);
  CHECK(props::energy_test_detectable_shift(64, 32, 0.01) > shift);  // power falls with dimension
  CHECK_THROWS_AS(props::energy_test_detectable_shift(0, 32, 0.01), InvalidArgument);
}
