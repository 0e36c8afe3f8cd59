// Pointwise checks: verdicts, shrunk witnesses that replay from their seed and recompute, the
// near-identity rule, and the planted faults each check must catch.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <memory>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/props/checks/check.hpp"
#include "handcentric/props/tolerance.hpp"
#include "mutants.hpp"

using namespace handcentric;
using props::Component;
using props::Group;

namespace {

props::CheckOptions fast(int cases = 300) {
  props::CheckOptions options = props::eye_in_hand_options();
  options.cases = cases;
  return options;
}

// The witness is a real counterexample: recomputing it gives the same error, above tolerance.
void require_checked_witness(const props::SceneFunction& f, const props::Verdict& verdict) {
  REQUIRE_FALSE(verdict.invariant);
  REQUIRE(verdict.witness.has_value());
  const props::Witness& w = *verdict.witness;
  CHECK(props::recompute_error(f, w) == w.error);
  CHECK(w.error > w.tolerance);
  CHECK(w.tolerance == props::pointwise_tolerance(w.scene, w.g * w.scene));
}

}  // namespace

TEST_CASE("hand_centric_actions_and_observation_are_invariant_under_every_group", "[property]") {
  const auto hand_centric = std::make_shared<HandCentricRepresentation>();
  for (Group group : props::all_groups()) {
    for (const auto& [component, f] :
         {std::pair{Component::actions, props::actions_of(hand_centric)},
          std::pair{Component::observation, props::observation_of(hand_centric)}}) {
      const props::Verdict verdict = props::check_invariance(f, component, group, fast());
      INFO(props::to_string(component) << " under " << props::to_string(group));
      CHECK(verdict.invariant);
      CHECK(verdict.cases + verdict.near_identity_cases == 300);
      CHECK(verdict.cases > 200);
      CHECK(verdict.max_error < 1e-9);
      CHECK_FALSE(verdict.witness.has_value());
    }
  }
}

TEST_CASE("mutant_hand_centric_encoders_fail_the_invariance_check_with_checked_witnesses",
          "[property]") {
  for (const std::shared_ptr<const Representation>& mutant :
       {std::shared_ptr<const Representation>(
            std::make_shared<test::ForgetsRotationOnTranslation>()),
        std::shared_ptr<const Representation>(std::make_shared<test::UsesR0ForR0Transpose>())}) {
    for (Group group : {Group::rotation, Group::se2, Group::se3, Group::c8}) {
      INFO(mutant->name() << " under " << props::to_string(group));
      const auto f = props::actions_of(mutant);
      require_checked_witness(f, props::check_invariance(f, Component::actions, group, fast()));
    }
  }
}

TEST_CASE("a_witness_replays_bit_for_bit_from_its_seed", "[property]") {
  const auto f = props::actions_of(std::make_shared<RelativeRepresentation>());
  props::CheckOptions options = fast();
  options.seed = 77;
  const props::Verdict first =
      props::check_invariance(f, Component::actions, Group::rotation, options);
  const props::Verdict again =
      props::check_invariance(f, Component::actions, Group::rotation, options);
  REQUIRE(first.witness.has_value());
  REQUIRE(again.witness.has_value());
  CHECK(first.seed == 77);
  CHECK(props::format_witness(*first.witness) == props::format_witness(*again.witness));
  CHECK(first.max_error == again.max_error);
  CHECK(first.cases == again.cases);
  // Shrunk: RapidCheck reduces the scene to one action and no history.
  CHECK(first.witness->scene.chunk_length() == 1);
  CHECK(first.witness->scene.history_length() == 0);
}

TEST_CASE("flow_checks_use_a_fixed_eps_and_t_and_see_actionflow_change_pointwise", "[property]") {
  const auto actionflow = std::make_shared<ActionFlowTarget>();
  const auto hand_flow =
      std::make_shared<RectifiedFlow>(std::make_shared<HandCentricRepresentation>());
  const auto target = props::flow_target_of(actionflow, 1, 0.5);
  require_checked_witness(
      target, props::check_invariance(target, Component::flow_target, Group::rotation, fast()));
  CHECK(props::check_invariance(props::flow_target_of(hand_flow, 1, 0.5), Component::flow_target,
                                Group::se3, fast())
            .invariant);
  CHECK(props::check_invariance(props::flow_input_of(hand_flow, 1, 0.5), Component::flow_input,
                                Group::se3, fast())
            .invariant);
  CHECK(props::fixed_noise(5, 3) == props::fixed_noise(8, 3).head(5));
}

TEST_CASE("near_identity_transforms_are_run_but_not_counted", "[unit]") {
  Scene scene;
  scene.world_T_hand_history = {RigidTransform::from_translation(Eigen::Vector3d(3, 0, 0))};
  scene.world_T_hand_chunk = {RigidTransform::identity()};
  CHECK(props::length_scale(scene) == 3.0);
  CHECK(props::near_identity(RigidTransform::identity(), scene));
  CHECK(props::near_identity(
      RigidTransform(Rotation::exp(Eigen::Vector3d(0, 0, 1e-12)), Eigen::Vector3d::Zero()), scene));
  CHECK_FALSE(
      props::near_identity(RigidTransform::from_translation(Eigen::Vector3d(0, 1e-3, 0)), scene));
  CHECK_FALSE(props::near_identity(RigidTransform::planar(1e-4, 0, 0), scene));
  // The rotation group's edge cases (identity, 1e-12 rad) appear and are set apart.
  const auto f = props::actions_of(std::make_shared<HandCentricRepresentation>());
  const props::Verdict verdict =
      props::check_invariance(f, Component::actions, Group::rotation, fast(400));
  CHECK(verdict.near_identity_cases > 0);
  CHECK(verdict.cases + verdict.near_identity_cases == 400);
}

TEST_CASE("a_nan_output_is_a_failure_and_a_thrown_error_stops_the_check", "[unit]") {
  const props::SceneFunction nan_function = [](const Scene&) {
    return Eigen::VectorXd::Constant(3, std::numeric_limits<double>::quiet_NaN());
  };
  const props::Verdict verdict =
      props::check_invariance(nan_function, Component::actions, Group::translation, fast(50));
  CHECK_FALSE(verdict.invariant);
  CHECK(std::isinf(verdict.max_error));
  const props::SceneFunction throwing = [](const Scene&) -> Eigen::VectorXd {
    throw InvalidArgument("planted: this function refuses every scene");
  };
  CHECK_THROWS_WITH(props::check_invariance(throwing, Component::actions, Group::se3, fast(50)),
                    Catch::Matchers::Contains("planted"));
  props::CheckOptions none = fast(0);
  CHECK_THROWS_AS(props::check_invariance(nan_function, Component::actions, Group::se3, none),
                  InvalidArgument);
}

TEST_CASE("the_relative_tolerance_option_scales_what_counts_as_invariant", "[unit]") {
  // f moves by 1e-6 |p~|: a change far above 1e-9 (1 + L), far below 1e-3 (1 + L).
  const props::SceneFunction small_leak = [](const Scene& scene) -> Eigen::VectorXd {
    return 1e-6 * scene.world_T_hand0().translation();
  };
  props::CheckOptions options = fast(100);
  CHECK_FALSE(props::check_invariance(small_leak, Component::actions, Group::translation, options)
                  .invariant);
  options.relative_tolerance = 1e-3;
  CHECK(props::check_invariance(small_leak, Component::actions, Group::translation, options)
            .invariant);
  options.relative_tolerance = 0.0;
  CHECK_THROWS_AS(
      props::check_invariance(small_leak, Component::actions, Group::translation, options),
      InvalidArgument);
}
