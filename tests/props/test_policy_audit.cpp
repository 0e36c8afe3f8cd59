// The audit of whole policies (eq. 4): pointwise with shared noise, in distribution with
// independent noise (exactly where the chunk is affine in the noise), both views; each with a
// planted fault it must catch, and the fault that is equivariant in law only.
#include <catch2/catch.hpp>
#include <memory>
#include <sstream>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/props/audit.hpp"
#include "handcentric/props/checks/policy_audit.hpp"
#include "handcentric/props/random_network.hpp"
#include "handcentric/props/tolerance.hpp"
#include "mutants.hpp"

using namespace handcentric;
using props::Group;

namespace {

constexpr int kAuditChunk = 3;

// T_k = T_0 exp(step)^k, then + sigma * n_k in the world frame (the planted fault: noise in the
// wrong frame) or in the hand frame (R_0 n_k: equivariant). Affine in the noise n.
class NoisyStraightPolicy final : public props::NoisyPolicy {
 public:
  explicit NoisyStraightPolicy(bool world_frame_noise) : world_(world_frame_noise) {}
  std::string name() const override { return world_ ? "world_frame_noise" : "hand_frame_noise"; }
  Eigen::Index noise_dimension() const override { return 3 * kAuditChunk; }
  std::vector<RigidTransform> act(const Scene& o, const Eigen::VectorXd& noise) const override {
    Twist step;
    step << 0.05, 0.0, 0.01, 0.0, 0.1, 0.0;
    std::vector<RigidTransform> chunk;
    RigidTransform T = o.world_T_hand0();
    for (int k = 0; k < kAuditChunk; ++k) {
      T = T * RigidTransform::exp(step);
      const Eigen::Vector3d n = 0.1 * noise.segment<3>(3 * k);
      const Eigen::Vector3d shift =
          world_ ? n : Eigen::Vector3d(o.world_T_hand0().rotation().matrix() * n);
      chunk.push_back(RigidTransform::unchecked(T.rotation().matrix(), T.translation() + shift));
    }
    return chunk;
  }

 private:
  bool world_;
};

props::ClassifierOptions fast_audit() {
  props::ClassifierOptions options;
  options.check.cases = 100;
  options.distribution.cases = 5;
  return options;
}

}  // namespace

TEST_CASE("any_network_inside_the_hand_centric_outer_policy_is_equivariant_pointwise_and_in_law",
          "[property]") {
  const auto inner = std::make_shared<props::RandomOuterPolicy>(
      std::make_shared<HandCentricRepresentation>(), 6, kAuditChunk, std::vector<int>{16}, 3);
  props::ClassifierOptions options = fast_audit();
  options.law_from_pointwise = false;  // the law tested, not taken from the pointwise "yes"
  options.views = {props::View::eye_in_hand};
  options.check.shape.min_history = options.check.shape.max_history = 0;
  options.check.shape.max_hand_points = 0;
  const props::Classification c =
      props::classify_policy(std::make_shared<props::SeededPolicy>(inner), options);
  REQUIRE(c.verdicts.size() == 10);
  for (const props::Verdict& v : c.verdicts) {
    INFO(props::to_string(v.mode) << " " << props::to_string(v.group));
    CHECK(v.invariant);
    if (v.mode == props::Mode::distribution)
      CHECK(v.method == props::Method::energy_test);  // seeded: not affine
  }
}

TEST_CASE(
    "noise_in_the_world_frame_is_equivariant_in_law_under_rotations_only_and_is_decided_exactly",
    "[property]") {
  const NoisyStraightPolicy world(true), hand(false);
  const props::CheckOptions options = props::options_for(props::View::third_person);
  for (Group group : {Group::rotation, Group::c8, Group::se3}) {
    INFO(props::to_string(group));
    // Pointwise the same noise lands differently: the planted fault is caught ...
    CHECK_FALSE(props::check_policy_equivariance(world, group, options).invariant);
    CHECK(props::check_policy_equivariance(hand, group, options).invariant);
    // ... but N(0, I) is rotation invariant, so in law it is equivariant, exactly.
    const props::Verdict law = props::check_policy_distribution(world, group, options);
    CHECK(law.invariant);
    CHECK(law.method == props::Method::exact_gaussian);
  }
  CHECK(props::check_policy_equivariance(world, Group::translation, options).invariant);
}

TEST_CASE("a_policy_whose_decoder_forgets_R0_is_not_rotation_equivariant", "[property]") {
  const auto forgets = std::make_shared<props::RandomOuterPolicy>(
      std::make_shared<test::DecoderForgetsR0>(), 6, kAuditChunk, std::vector<int>{16}, 4);
  props::CheckOptions options = props::eye_in_hand_options();
  options.shape.min_history = options.shape.max_history = 0;
  options.shape.max_hand_points = 0;
  const props::SeededPolicy seeded(forgets);
  const props::Verdict pointwise =
      props::check_policy_equivariance(seeded, Group::rotation, options);
  CHECK_FALSE(pointwise.invariant);
  REQUIRE(pointwise.witness.has_value());
  CHECK(props::check_policy_distribution(seeded, Group::translation, options)
            .invariant);  // R_0 untouched
}

TEST_CASE("a_mean_moved_by_a_frame_mix_up_is_caught_in_law_by_the_paired_mean_test", "[property]") {
  // Not affine in the noise (cubed), and the mean of the chunk moves by 0.05 under a rotation:
  // far below what 32 draws of the energy test see in 36 dimensions, plain to the paired test.
  class MixedFrames final : public props::NoisyPolicy {
   public:
    std::string name() const override { return "mixed_frames"; }
    Eigen::Index noise_dimension() const override { return 3 * kAuditChunk; }
    std::vector<RigidTransform> act(const Scene& o, const Eigen::VectorXd& noise) const override {
      std::vector<RigidTransform> chunk;
      for (int k = 0; k < kAuditChunk; ++k) {
        const Eigen::Vector3d n = 0.3 * noise.segment<3>(3 * k).array().cube().matrix();
        // A world-frame offset (0.05 along world x) where a hand-frame one was meant.
        chunk.push_back(o.world_T_hand0() * RigidTransform::from_translation(n) *
                        RigidTransform::from_translation(Eigen::Vector3d(0.1 * (k + 1), 0, 0)));
        chunk.back() = RigidTransform::from_translation(Eigen::Vector3d(0.05, 0, 0)) * chunk.back();
      }
      return chunk;
    }
  };
  const MixedFrames mixed;
  props::CheckOptions options = props::eye_in_hand_options();
  const props::Verdict law = props::check_policy_distribution(mixed, Group::rotation, options);
  CHECK_FALSE(law.invariant);
  // The rotations do not depend on the noise (affine: compared exactly); the positions do.
  CHECK(law.method == props::Method::partly_exact);
  REQUIRE(law.witness.has_value());
  CHECK_THAT(law.witness->detail, Catch::Matchers::Contains("paired mean test"));
  CHECK_THAT(law.witness->detail, Catch::Matchers::Contains("affine in eps"));
}

TEST_CASE("student_t_and_the_paired_mean_test", "[unit]") {
  CHECK(props::student_t_two_sided_p(0.0, 10.0) == Approx(1.0));
  CHECK(props::student_t_two_sided_p(2.228, 10.0) ==
        Approx(0.05).epsilon(0.01));  // the 97.5% quantile, 10 df
  CHECK(props::student_t_two_sided_p(12.706, 1.0) == Approx(0.05).epsilon(0.01));
  Eigen::MatrixXd zero_mean(6, 2), shifted(6, 2);
  zero_mean << 1, -1, -1, 1, 1, -1, -1, 1, 0.5, -0.5, -0.5, 0.5;
  shifted = zero_mean.array() + 3.0;
  CHECK(props::paired_mean_test(zero_mean, 1e-12) > 0.5);
  CHECK(props::paired_mean_test(shifted, 1e-12) < 0.01);
  CHECK(props::paired_mean_test(Eigen::MatrixXd::Constant(4, 3, 0.2), 1e-12) ==
        0.0);  // a constant offset
}

TEST_CASE("a_chunk_pose_whose_rotation_block_is_not_a_rotation_stops_the_audit", "[unit]") {
  // The planted fault: a decoder that returns 2 R instead of R. Its chunks cannot be compared as
  // poses, so no verdict: an error naming the pose and the numbers.
  class ScaledRotation final : public props::NoisyPolicy {
   public:
    std::string name() const override { return "scaled_rotation"; }
    Eigen::Index noise_dimension() const override { return 1; }
    std::vector<RigidTransform> act(const Scene& o, const Eigen::VectorXd&) const override {
      const RigidTransform& T = o.world_T_hand0();
      return {T, RigidTransform::unchecked(2.0 * T.rotation().matrix(), T.translation())};
    }
  };
  props::CheckOptions options = props::eye_in_hand_options();
  options.cases = 20;
  for (Group group : {Group::translation, Group::se3}) {
    CHECK_THROWS_WITH(props::check_policy_equivariance(ScaledRotation(), group, options),
                      Catch::Contains("chunk pose 1 (T_2)") && Catch::Contains("not a rotation") &&
                          (Catch::Contains("det R = 8") || Catch::Contains("det R = 7.99999999")));
    CHECK_THROWS_AS(props::check_policy_distribution(ScaledRotation(), group, options),
                    InvalidArgument);
  }
  CHECK(props::pose_defect(Eigen::Matrix4d::Identity()).empty());
}

namespace {

// A hand-centric policy (Theorem 1: T_k = T_0 exp(step)^k) whose sampler adds noise to the
// positions in the WORLD frame with per-axis scales, as a per-dimension min/max normalizer in
// world coordinates does to diffusion noise, and whose rotations depend on the noise
// non-linearly in the hand frame (R_k exp(0.05 tanh(n[3..6]))): equivariant in law on their own.
// Anisotropic scales make the law of g a(o, n) differ from that of a(g o, n) under rotations in
// the covariance alone (the means agree); isotropic ones do not (N(0, s^2 I) is rotation
// invariant). `curved` passes the world noise through n (1 + 0.3 |n|^2) (rotation invariant in
// law, zero mean), so that no coordinate is affine and only the tests can see it.
class WorldNoiseHandCentric final : public props::NoisyPolicy {
 public:
  WorldNoiseHandCentric(const Eigen::Vector3d& scales, bool curved = false)
      : scales_(scales), curved_(curved) {}
  std::string name() const override { return "hand_centric_world_noise"; }
  Eigen::Index noise_dimension() const override { return 6; }
  std::vector<RigidTransform> act(const Scene& o, const Eigen::VectorXd& noise) const override {
    Twist step;
    step << 0.05, 0.0, 0.01, 0.0, 0.1, 0.0;
    const Eigen::Vector3d wobble = 0.05 * noise.segment<3>(3).array().tanh().matrix();
    Eigen::Vector3d n = noise.head<3>();
    if (curved_) n *= 1.0 + 0.3 * n.squaredNorm();
    const Eigen::Vector3d shift = scales_.asDiagonal() * n;
    std::vector<RigidTransform> chunk;
    RigidTransform T = o.world_T_hand0();
    for (int k = 0; k < kAuditChunk; ++k) {
      T = T * RigidTransform::exp(step);
      chunk.push_back(RigidTransform::unchecked(
          T.rotation().matrix() * Rotation::exp(wobble).matrix(), T.translation() + shift));
    }
    return chunk;
  }

 private:
  Eigen::Vector3d scales_;
  bool curved_;
};

const Eigen::Vector3d kAnisotropic(0.01, 0.01, 0.03), kIsotropic(0.01, 0.01, 0.01);

}  // namespace

TEST_CASE("anisotropic_world_noise_is_not_equivariant_in_law_and_is_decided_exactly",
          "[property]") {
  // The false "yes" this audit once gave: now the positions, affine in the noise, are compared
  // as Gaussian laws and their covariances differ, on every seed.
  const WorldNoiseHandCentric anisotropic(kAnisotropic), isotropic(kIsotropic);
  for (std::uint64_t seed = 1; seed <= 50; ++seed) {
    props::CheckOptions options = props::eye_in_hand_options();
    options.seed = seed;
    for (Group group : {Group::rotation, Group::se3}) {
      INFO("seed " << seed << ", " << props::to_string(group));
      const props::Verdict verdict = props::check_policy_distribution(anisotropic, group, options);
      CHECK_FALSE(verdict.invariant);
      CHECK(verdict.method == props::Method::partly_exact);
      REQUIRE(verdict.witness.has_value());
      CHECK_THAT(verdict.witness->detail, Catch::Matchers::Contains("covariances by"));
    }
    INFO("seed " << seed);
    const props::Verdict same =
        props::check_policy_distribution(isotropic, Group::rotation, options);
    CHECK(same.invariant);
    CHECK(same.method == props::Method::partly_exact);
    CHECK(same.detectable_scale_ratio.has_value());
    // A translation turns no axis: world noise of any shape is fine.
    CHECK(props::check_policy_distribution(anisotropic, Group::translation, options).invariant);
  }
}

TEST_CASE("without_the_exact_split_and_the_scale_test_anisotropic_world_noise_passes",
          "[property]") {
  // The planted fault: the comparison as it was (every coordinate tested, energy and paired mean
  // tests only, 32 draws) says "yes", so the new parts are what catch it.
  const WorldNoiseHandCentric anisotropic(kAnisotropic);
  props::DistributionOptions blind;
  blind.exact_affine_part = false;
  blind.scale_test = false;
  props::DistributionOptions scale_only;
  scale_only.exact_affine_part = false;
  int blind_yes = 0, scale_no = 0;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    props::CheckOptions options = props::eye_in_hand_options();
    options.seed = seed;
    const props::Verdict verdict =
        props::check_policy_distribution(anisotropic, Group::rotation, options, blind);
    CHECK(verdict.method == props::Method::energy_test);
    CHECK_FALSE(verdict.detectable_scale_ratio.has_value());
    blind_yes += verdict.invariant ? 1 : 0;
    // The scale test alone, all coordinates tested, finds it too.
    scale_no += props::check_policy_distribution(anisotropic, Group::rotation, options, scale_only)
                        .invariant
                    ? 0
                    : 1;
  }
  CHECK(blind_yes == 5);
  CHECK(scale_no == 5);
}

TEST_CASE("anisotropic_world_noise_through_a_curve_is_found_by_the_scale_test", "[property]") {
  // No coordinate is affine in the noise, so nothing is compared exactly: the scale test finds
  // it, the energy and paired mean tests alone do not.
  const WorldNoiseHandCentric curved(kAnisotropic, true), isotropic(kIsotropic, true);
  props::DistributionOptions no_scale;
  no_scale.scale_test = false;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    props::CheckOptions options = props::eye_in_hand_options();
    options.seed = seed;
    INFO("seed " << seed);
    const props::Verdict verdict =
        props::check_policy_distribution(curved, Group::rotation, options);
    CHECK_FALSE(verdict.invariant);
    CHECK(verdict.method == props::Method::energy_test);
    REQUIRE(verdict.witness.has_value());
    CHECK_THAT(verdict.witness->detail, Catch::Matchers::Contains("scale test"));
    CHECK(props::check_policy_distribution(curved, Group::rotation, options, no_scale).invariant);
    const props::Verdict same =
        props::check_policy_distribution(isotropic, Group::rotation, options);
    CHECK(same.invariant);
    REQUIRE(same.detectable_scale_ratio.has_value());
    CHECK(*same.detectable_scale_ratio <= 2.0);
  }
}

TEST_CASE("a_tested_yes_states_the_mean_shift_and_the_scale_ratio_it_would_find", "[unit]") {
  props::Verdict verdict;
  verdict.component = props::Component::policy;
  verdict.mode = props::Mode::distribution;
  verdict.group = Group::rotation;
  verdict.view = props::View::eye_in_hand;
  verdict.method = props::Method::partly_exact;
  verdict.invariant = true;
  verdict.detectable_shift = 0.034;
  verdict.detectable_scale_ratio = 1.99;
  props::Classification policy;
  policy.name = "p";
  policy.verdicts = {verdict};
  props::AuditOptions options;
  options.groups = {Group::rotation};
  options.views = {props::View::eye_in_hand};
  std::ostringstream text;
  props::print_audit(text, {policy}, options);
  CHECK_THAT(text.str(), Catch::Matchers::Contains("a mean shift of 0.034 (Euclidean norm") &&
                             Catch::Matchers::Contains("m for positions") &&
                             Catch::Matchers::Contains("changed by a factor 1.99") &&
                             Catch::Matchers::Contains("with 90% power"));
  CHECK_THAT(text.str(), Catch::Matchers::Contains("yes  0.0e+00~"));
  const std::string json = props::policy_audit_json({policy});
  CHECK_THAT(json, Catch::Matchers::Contains("\"detectable_scale_ratio\": 1.99") &&
                       Catch::Matchers::Contains("\"method\": \"partly_exact\""));
}

namespace {

// Equivariant (a hand-frame step, hand-frame noise) except where the hand is within
// `radius` of a fixed world point: there a world-frame push is added, as a policy that reads a
// camera fixed in the world acts differently only when the scene is in that camera's view. The
// planted fault of the next test: it breaks the symmetry on a small part of the scenes.
class WorldSpotPolicy final : public props::NoisyPolicy {
 public:
  explicit WorldSpotPolicy(double radius) : radius_(radius) {}
  std::string name() const override { return "world_spot"; }
  Eigen::Index noise_dimension() const override { return 3 * kAuditChunk; }
  std::vector<RigidTransform> act(const Scene& o, const Eigen::VectorXd& noise) const override {
    const RigidTransform& T_0 = o.world_T_hand0();
    const bool seen = (T_0.translation() - Eigen::Vector3d(1.0, 0.0, 0.0)).norm() < radius_;
    std::vector<RigidTransform> chunk;
    for (int k = 0; k < kAuditChunk; ++k) {
      const Eigen::Vector3d hand_step =
          Eigen::Vector3d(0.01 * (k + 1), 0.0, 0.0) + 0.01 * noise.segment<3>(3 * k);
      Eigen::Vector3d p = T_0 * hand_step;
      if (seen) p += Eigen::Vector3d(0.05, 0.0, 0.0);
      chunk.push_back(RigidTransform::unchecked(T_0.rotation().matrix(), p));
    }
    return chunk;
  }

 private:
  double radius_;
};

}  // namespace

// The in-distribution check runs the pointwise check's witness as one more case
// (CheckOptions::extra_cases): a policy that breaks the symmetry only where the hand is near one
// world point fails pointwise (1000 cases find the spot) while the 10 drawn in-distribution
// cases all miss it, and a "yes in distribution" beside a pointwise NO whose law differs too
// would be a false yes. With the witness the in-distribution verdict is NO, decided exactly (the
// chunk is affine in the noise), and says where its witness came from. The drawn cases alone
// (check_policy_distribution without extra cases) pass: the gap the witness closes.
TEST_CASE("an_in_distribution_check_also_runs_the_pointwise_witness", "[property]") {
  const auto policy = std::make_shared<WorldSpotPolicy>(0.5);
  props::ClassifierOptions options;
  options.views = {props::View::eye_in_hand};
  options.groups = {Group::translation};
  const props::Classification c = props::classify_policy(policy, options);
  REQUIRE(c.verdicts.size() == 2);
  const props::Verdict& pointwise = c.verdicts[0];
  const props::Verdict& in_law = c.verdicts[1];
  REQUIRE(pointwise.mode == props::Mode::pointwise);
  REQUIRE(in_law.mode == props::Mode::distribution);
  CHECK_FALSE(pointwise.invariant);
  CHECK_FALSE(in_law.invariant);
  CHECK(in_law.method == props::Method::exact_gaussian);
  REQUIRE(in_law.witness);
  // The pointwise witness, run as an extra case, fails in law there and on the same case moved
  // off it by a rounding-sized amount (the rule that tells a bin edge from a breaking): the law's
  // witness is that moved scene.
  const Eigen::Vector3d law_p = in_law.witness->scene.world_T_hand0().translation();
  const Eigen::Vector3d pointwise_p = pointwise.witness->scene.world_T_hand0().translation();
  CHECK((law_p - pointwise_p).norm() <= 1e-6 * (1.0 + pointwise_p.norm()));
  CHECK(in_law.witness->off_case);
  CHECK_THAT(in_law.note, Catch::Contains("the witness is the pointwise check's"));
  const props::Verdict drawn_only = props::check_policy_distribution(
      *policy, Group::translation, props::with_view(options.check, props::View::eye_in_hand),
      options.distribution);
  CHECK(drawn_only.invariant);
}
