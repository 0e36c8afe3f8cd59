// Head c8ddpm_avg (c8_averaged.hpp): each DDIM step averaged over C8 makes the whole policy
// exactly C8-equivariant, pointwise, whatever the network learned, with noise or without; it is
// not SE(2)-equivariant (C8 fixes the centre, so no translation); and the audit catches the two
// planted faults the construction must not have: an average over 7 of the 8 elements, and the
// chunks averaged after sampling with a different noise per element.
#include <catch2/catch.hpp>

#include <memory>
#include <numbers>

#include "fixtures.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/policy/c8_averaged.hpp"
#include "handcentric/policy/c8_planar.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/policy/trainer.hpp"
#include "handcentric/props/audit.hpp"
#include "handcentric/props/checks/policy_audit.hpp"
#include "handcentric/props/checks/profile.hpp"
#include "throws.hpp"

using namespace handcentric;
using namespace handcentric::policy;

namespace {

// Peg-like planar scenes (cm): H = 2, K = 4, two eye-in-hand points in the plane.
std::vector<Scene> planar_training_scenes(int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  auto uniform = [&rng](double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
  };
  std::vector<Scene> scenes;
  for (int i = 0; i < count; ++i) {
    Scene scene;
    for (int h = 0; h < 3; ++h)
      scene.world_T_hand_history.push_back(RigidTransform::planar(
          uniform(-std::numbers::pi, std::numbers::pi), uniform(-50, 50), uniform(-50, 50)));
    for (int k = 0; k < 4; ++k)
      scene.world_T_hand_chunk.push_back(RigidTransform::planar(
          uniform(-std::numbers::pi, std::numbers::pi), uniform(-50, 50), uniform(-50, 50)));
    for (int p = 0; p < 2; ++p) scene.hand_points.emplace_back(uniform(-5, 5), uniform(-5, 5), 0);
    scenes.push_back(scene);
  }
  return scenes;
}

LearnedPolicy trained(HeadKind head, double noise_scale) {
  PolicyConfig config = test::small_config(head, "absolute", 60);
  config.noise_scale = noise_scale;
  return train_policy(config, planar_training_scenes(6, 11), 5);
}

// The audit of `audit --model` for a peg2d model: planar eye-in-hand scenes of the model's
// shape, pointwise, under c8 and se2.
// `precision`: the audit's floor and rounding probes (its --precision).
std::vector<props::Verdict> audit(std::shared_ptr<const ChunkPolicy> policy, int cases = 60,
                                  props::Precision precision = props::Precision::float64) {
  props::ClassifierOptions options;
  options.check.relative_tolerance = props::precision_relative_tolerance(precision);
  options.check.unit_roundoff = props::probe_unit_roundoff(precision);
  options.check.output_unit_roundoff = props::unit_roundoff(precision);
  options.groups = {props::Group::c8, props::Group::se2};
  options.views = {props::View::eye_in_hand};
  options.in_distribution = false;
  options.precision_note = false;
  options.check.cases = cases;
  options.check.shape.planar = true;
  options.check.shape.min_history = options.check.shape.max_history = 2;
  options.check.shape.min_hand_points = options.check.shape.max_hand_points = 2;
  options.check.shape.max_chunk = 4;
  const props::Classification c =
      props::classify_policy(std::make_shared<props::SeededPolicy>(std::move(policy)), options);
  REQUIRE(c.verdicts.size() == 2);
  return c.verdicts;
}

// The sampler of a trained c8ddpm_avg model with a planted fault, in a world-frame policy.
class FaultyAveraging final : public ChunkPolicy {
 public:
  enum class Fault { seven_elements, chunks };
  FaultyAveraging(std::shared_ptr<const LearnedPolicy> model, Fault fault)
      : model_(std::move(model)), fault_(fault) {}
  std::string name() const override { return "faulty c8ddpm_avg"; }
  std::vector<RigidTransform> act(const Scene& observation, std::uint64_t seed) const override {
    const Representation& absolute = model_->representation();
    std::mt19937_64 rng(seed);
    const c8::Layout actions = c8::action_layout(model_->config());
    Eigen::VectorXd a;
    if (fault_ == Fault::seven_elements) {
      const Eigen::MatrixXd o = absolute.encode_observation(observation);
      a = c8::averaged_sample(model_->head(), o, rng, {0, 1, 2, 3, 4, 5, 6}).col(0);
    } else {
      // Sample each element's chunk with the unaveraged sampler and the next noise of one
      // stream, move it back, average the chunks.
      Eigen::VectorXd sum = Eigen::VectorXd::Zero(actions.planar_size());
      for (int k = 0; k < 8; ++k) {
        const Scene moved =
            RigidTransform::planar(k * std::numbers::pi / 4.0, 0.0, 0.0) * observation;
        const Eigen::MatrixXd o = absolute.encode_observation(moved);
        const Eigen::VectorXd chunk = c8::averaged_sample(model_->head(), o, rng, {0}).col(0);
        sum += c8::act_planar(-k, {0.0, 0.0}, c8::encode_planar(chunk, actions), actions);
      }
      a = c8::decode_planar(sum / 8.0, actions);
    }
    return absolute.decode_actions(a, observation.world_T_hand0());
  }

 private:
  std::shared_ptr<const LearnedPolicy> model_;
  Fault fault_;
};

}  // namespace

TEST_CASE("c8ddpm_avg_and_c8flow_avg_are_c8_equivariant_pointwise_and_not_se2_equivariant",
          "[unit][property]") {
  for (const auto& [head, noise_scale] :
       {std::pair{HeadKind::c8ddpm_avg, 0.0}, std::pair{HeadKind::c8ddpm_avg, 1.0},
        std::pair{HeadKind::c8flow_avg, 0.0}, std::pair{HeadKind::c8flow_avg, 1.0}}) {
    INFO(to_string(head) << ", noise_scale " << noise_scale);
    auto model = std::make_shared<LearnedPolicy>(trained(head, noise_scale));
    // The network runs in float32. Without noise every step stays on C8's fixed points and the
    // chunks agree to double rounding; with noise the eight images of a step round differently
    // in float32 (outputs of ~50 m agree to ~1e-7 of their size), so that audit is at float32,
    // as `audit --model` advises for it: each case draws its own noise, and at the float64
    // floor most of them show that rounding.
    const auto verdicts = audit(
        model, 60, noise_scale == 0.0 ? props::Precision::float64 : props::Precision::float32);
    INFO(props::to_string(verdicts[0].group) << ": " << verdicts[0].max_error);
    CHECK(verdicts[0].group == props::Group::c8);
    CHECK(verdicts[0].invariant);
    CHECK(verdicts[0].cases > 30);
    if (noise_scale == 0.0) {
      CHECK(verdicts[0].max_error < 1e-9);  // exact up to double rounding, nowhere a jump
      CHECK(verdicts[0].discontinuities == 0);
    }
    CHECK(verdicts[1].group == props::Group::se2);
    CHECK_FALSE(verdicts[1].invariant);
    CHECK(verdicts[1].max_error > 1e-3);
    // The model file keeps it: the same sampler after a round trip.
    const LearnedPolicy loaded = deserialize_model(serialize_model(*model), to_string(head));
    CHECK(loaded.head().kind() == head);
    const Scene scene = planar_training_scenes(1, 99)[0];
    CHECK(loaded.action_vector(scene, 3) == model->action_vector(scene, 3));
  }
}

TEST_CASE("c8ddpm_avg_profile_is_zero_on_c8_and_not_between", "[unit][property]") {
  // How far from equivariant (props/profile.hpp), on a trained model: at the multiples of 45 deg
  // about its centre the chunk moves with g up to rounding; at the angles between it does not.
  auto model = std::make_shared<LearnedPolicy>(trained(HeadKind::c8ddpm_avg, 0.0));
  props::ProfileOptions options;
  options.scenes = 4;
  options.samples = 4;
  options.shape.planar = true;
  options.shape.min_history = options.shape.max_history = 2;
  options.shape.min_hand_points = options.shape.max_hand_points = 2;
  options.shape.max_chunk = 4;
  const props::Profile p =
      props::profile_policy(props::SeededPolicy(model), props::Group::c8, options);
  for (const props::ProfilePoint& point : p.points) {
    INFO("angle " << point.size << ": " << point.pointwise.median);
    if (point.in_group)
      CHECK(point.pointwise.max < 1e-9);
    else
      CHECK(point.pointwise.median > 1e-3);
  }
}

TEST_CASE("c8ddpm_and_c8flow_planar_trained_alike_are_c8_equivariant_only_as_far_as_they_learned",
          "[unit][property]") {
  // The same networks and training without the averaged sampler: the audit tells them apart.
  for (const HeadKind head : {HeadKind::c8ddpm, HeadKind::c8flow_planar}) {
    INFO(to_string(head));
    const auto verdicts = audit(std::make_shared<LearnedPolicy>(trained(head, 0.0)), 30);
    CHECK_FALSE(verdicts[0].invariant);
  }
}

TEST_CASE("the_audit_catches_an_average_over_seven_of_the_eight_elements", "[unit][property]") {
  for (const HeadKind head : {HeadKind::c8ddpm_avg, HeadKind::c8flow_avg}) {
    INFO(to_string(head));
    auto model = std::make_shared<LearnedPolicy>(trained(head, 0.0));
    const auto verdicts =
        audit(std::make_shared<FaultyAveraging>(model, FaultyAveraging::Fault::seven_elements), 30);
    CHECK_FALSE(verdicts[0].invariant);
    REQUIRE(verdicts[0].witness);
    CHECK(verdicts[0].witness->error > 1e-6);
  }
}

TEST_CASE("the_audit_catches_chunks_averaged_after_sampling_with_a_noise_per_element",
          "[unit][property]") {
  auto model = std::make_shared<LearnedPolicy>(trained(HeadKind::c8ddpm_avg, 1.0));
  const auto verdicts =
      audit(std::make_shared<FaultyAveraging>(model, FaultyAveraging::Fault::chunks), 30);
  CHECK_FALSE(verdicts[0].invariant);
  REQUIRE(verdicts[0].witness);
  CHECK(verdicts[0].witness->error > 1e-6);
}

TEST_CASE("c8ddpm_avg_trains_the_weights_and_budget_of_c8ddpm", "[unit]") {
  // The two Table 1 rows differ by the sampler alone: averaged over the augmented head's
  // weights, the sampler gives the averaged head's chunk bit for bit.
  CHECK(training_budget(HeadKind::c8ddpm_avg, 500) == training_budget(HeadKind::c8ddpm, 500));
  const LearnedPolicy averaged = trained(HeadKind::c8ddpm_avg, 1.0);
  const LearnedPolicy augmented = trained(HeadKind::c8ddpm, 1.0);
  const Eigen::MatrixXd o =
      averaged.representation().encode_observation(planar_training_scenes(1, 8)[0]);
  std::mt19937_64 rng_a(3), rng_b(3);
  CHECK(c8::averaged_sample(augmented.head(), o, rng_a) == averaged.head().sample_double(o, rng_b));
  // So Table 1 trains c8_centre once and gives c8_averaged its weights: the model file is the
  // one training c8ddpm_avg writes, byte for byte.
  CHECK(trained_as(HeadKind::c8ddpm_avg) == HeadKind::c8ddpm);
  CHECK(serialize_model(with_head_kind(augmented, HeadKind::c8ddpm_avg)) ==
        serialize_model(averaged));
  CHECK(serialize_model(with_head_kind(averaged, HeadKind::c8ddpm)) == serialize_model(augmented));
  // The comparison can fail: another training seed is another model.
  PolicyConfig config = test::small_config(HeadKind::c8ddpm, "absolute", 60);
  config.noise_scale = 1.0;
  const LearnedPolicy reseeded = train_policy(config, planar_training_scenes(6, 11), 6);
  CHECK(serialize_model(with_head_kind(reseeded, HeadKind::c8ddpm_avg)) !=
        serialize_model(averaged));
  // A head that trains other weights is refused, naming both.
  CHECK(trained_as(HeadKind::c8flow_planar) == HeadKind::c8flow_planar);
  HC_CHECK_THROWS(with_head_kind(augmented, HeadKind::c8flow_planar), InvalidArgument,
                  Catch::Contains("a c8ddpm model cannot be given head c8flow_planar"));
}

TEST_CASE("c8flow_avg_trains_the_weights_and_budget_of_c8flow_planar", "[unit]") {
  CHECK(trained_as(HeadKind::c8flow_avg) == HeadKind::c8flow_planar);
  CHECK(training_budget(HeadKind::c8flow_avg, 500) ==
        training_budget(HeadKind::c8flow_planar, 500));
  // The flow inside keeps the 8x budget up to the general cap; the DDPM stops at the C8 cap.
  CHECK(training_budget(HeadKind::c8flow_avg, 5000) == kBudgetMaxSteps);
  CHECK(training_budget(HeadKind::c8ddpm_avg, 5000) == kC8BudgetMaxSteps);
  const LearnedPolicy averaged = trained(HeadKind::c8flow_avg, 1.0);
  const LearnedPolicy augmented = trained(HeadKind::c8flow_planar, 1.0);
  CHECK(serialize_model(with_head_kind(augmented, HeadKind::c8flow_avg)) ==
        serialize_model(averaged));
  HC_CHECK_THROWS(with_head_kind(augmented, HeadKind::c8ddpm_avg), InvalidArgument,
                  Catch::Contains("a c8flow_planar model cannot be given head c8ddpm_avg"));
}

TEST_CASE("the_averaged_sampler_refuses_other_heads_and_bad_elements", "[unit]") {
  const LearnedPolicy model = trained(HeadKind::c8ddpm_avg, 0.0);
  const Eigen::MatrixXd o =
      model.representation().encode_observation(planar_training_scenes(1, 3)[0]);
  std::mt19937_64 rng(1);
  HC_CHECK_THROWS(c8::averaged_sample(model.head(), o, rng, {}), InvalidArgument,
                  Catch::Contains("at least one"));
  HC_CHECK_THROWS(c8::averaged_sample(model.head(), o, rng, {0, 8}), InvalidArgument,
                  Catch::Contains("8 is not one of 0..7"));
  PolicyConfig flow = test::small_config(HeadKind::flow, "absolute", 5);
  const LearnedPolicy other = train_policy(flow, planar_training_scenes(3, 4), 1);
  HC_CHECK_THROWS(c8::averaged_sample(other.head(), o, rng), InvalidArgument,
                  Catch::Contains("--head c8ddpm_avg"));
  // The element nearest to the hand's heading: round(theta / 45 deg) mod 8.
  Eigen::VectorXd planar = Eigen::VectorXd::Zero(5);
  for (const auto& [theta, k] : {std::pair{-0.1, 0}, std::pair{-0.5, 7}, std::pair{1.0, 1},
                                 std::pair{3.1, 4}, std::pair{-3.1, 4}}) {
    planar[3] = std::cos(theta);
    planar[4] = std::sin(theta);
    CHECK(c8::heading_sector(planar) == k);
  }
}
