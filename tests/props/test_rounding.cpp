// How a pointwise case is decided against the map's own rounding (check.hpp): a float32 policy
// that leaks 0.6 mm is "NO" at every scale while the same policy without the leak is "yes";
// a hand-centric map quantized into bins is invariant with its bin-edge cases counted, while
// bins taken in the world frame are "NO" with a witness away from any edge; a check with no far
// case, or whose function cannot answer, gives no verdict.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/props/checks/check.hpp"
#include "handcentric/props/checks/classifier.hpp"
#include "handcentric/props/checks/policy_audit.hpp"
#include "handcentric/props/tolerance.hpp"

using namespace handcentric;
using props::Component;
using props::Group;

namespace rounding_test {

constexpr int kChunk = 4;

// A hand-centric policy computed in float32 end to end, as a PyTorch policy is: the hand-frame
// chunk T_0^{-1} T_k is fixed, T_0 and the product are rounded to float. With `leak`, each
// chunk translation also moves by 3e-5 times the hand's world position: 0.3 mm at 10 m, 0.6 mm
// between a scene and its transform (this task's clearance is 1 mm).
class Float32Policy final : public props::NoisyPolicy {
 public:
  explicit Float32Policy(bool leak) : leak_(leak) {}
  std::string name() const override { return leak_ ? "float32_leak" : "float32_hand_centric"; }
  Eigen::Index noise_dimension() const override { return 1; }
  std::vector<RigidTransform> act(const Scene& o, const Eigen::VectorXd&) const override {
    const Eigen::Matrix4f world_T_hand0 = o.world_T_hand0().matrix().cast<float>();
    Twist step;
    step << 0.02, -0.01, 0.03, 0.1, 0.05, -0.2;
    std::vector<RigidTransform> chunk;
    Eigen::Matrix4d hand0_T_handk = Eigen::Matrix4d::Identity();
    for (int k = 0; k < kChunk; ++k) {
      hand0_T_handk = hand0_T_handk * RigidTransform::exp(step).matrix();
      Eigen::Matrix4f world_T_handk = world_T_hand0 * hand0_T_handk.cast<float>();
      if (leak_) {
        world_T_handk.block<3, 1>(0, 3) += 3e-5f * world_T_hand0.block<3, 1>(0, 3);
      }
      const Eigen::Matrix4d M = world_T_handk.cast<double>();
      chunk.push_back(RigidTransform::unchecked(M.topLeftCorner<3, 3>(), M.topRightCorner<3, 1>()));
    }
    return chunk;
  }

 private:
  bool leak_;
};

// Roll, pitch and yaw of R (ZYX), in radians.
Eigen::Vector3d euler(const Eigen::Matrix3d& R) {
  return Eigen::Vector3d(std::atan2(R(2, 1), R(2, 2)), std::asin(std::clamp(-R(2, 0), -1.0, 1.0)),
                         std::atan2(R(1, 0), R(0, 0)));
}

// A tokenized-action map: each chunk pose T_1..T_K as 1 cm voxels and 5 degree Euler bins,
// expressed in the hand frame at T_0 (invariant by construction) or in the world frame. A hand at
// rest (T_k = T_0, one scene in eight) puts T_0^{-1} T_k's Euler angles on the bin edge at 0:
// a rounding of 1e-16 either way lands in bin 0 or bin -1.
class BinnedPoses final : public Representation {
 public:
  explicit BinnedPoses(bool hand_frame) : hand_(hand_frame) {}
  std::string name() const override { return hand_ ? "binned_hand_centric" : "binned_world"; }
  Eigen::VectorXd encode_actions(const Scene& scene) const override {
    const RigidTransform frame = hand_ ? scene.world_T_hand0().inverse() : RigidTransform();
    const auto& chunk = scene.world_T_hand_chunk;
    Eigen::VectorXd out(6 * static_cast<Eigen::Index>(chunk.size()));
    for (std::size_t k = 0; k < chunk.size(); ++k) {
      const RigidTransform T = frame * chunk[k];
      const Eigen::Index at = 6 * static_cast<Eigen::Index>(k);
      out.segment<3>(at) = (T.translation() / kVoxel).array().floor().matrix();
      out.segment<3>(at + 3) = (euler(T.rotation().matrix()) / kAngleBin).array().floor().matrix();
    }
    return out;
  }
  Eigen::VectorXd encode_observation(const Scene&) const override { return {}; }
  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd&,
                                             const RigidTransform&) const override {
    throw InvalidArgument("a binned map does not decode");
  }

  static constexpr double kVoxel = 0.01;
  static constexpr double kAngleBin = 5.0 * 3.14159265358979323846 / 180.0;

 private:
  bool hand_;
};

props::CheckOptions float32_options(std::uint64_t seed) {
  props::CheckOptions options = props::eye_in_hand_options();
  options.cases = 100;
  options.seed = seed;
  options.relative_tolerance = props::kFloat32RelativeTolerance;
  options.unit_roundoff = props::kFloat32UnitRoundoff;
  return options;
}

}  // namespace rounding_test

using namespace rounding_test;

TEST_CASE("a_float32_policy_leaking_0.6_mm_fails_on_every_seed_and_without_the_leak_holds",
          "[property]") {
  const Float32Policy leaky(true), clean(false);
  for (std::uint64_t seed = 1; seed <= 50; ++seed) {
    INFO("seed " << seed);
    const props::Verdict leak =
        props::check_policy_equivariance(leaky, Group::translation, float32_options(seed));
    CHECK_FALSE(leak.invariant);
    REQUIRE(leak.witness.has_value());
    CHECK(leak.witness->error > leak.witness->tolerance);
    CHECK(leak.witness->length_scale > 0.0);
    CHECK(props::check_policy_equivariance(clean, Group::translation, float32_options(seed))
              .invariant);
    CHECK(props::check_policy_equivariance(clean, Group::se3, float32_options(seed)).invariant);
  }
}

TEST_CASE("mutant_the_old_float32_rule_lets_the_0.6_mm_leak_through", "[property]") {
  // The fault the new rule fixes: a floor of 1e-4 (1 + L) allows ~1 mm at L = 10 m.
  const Float32Policy leaky(true);
  int passed = 0;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    props::CheckOptions old_rule = float32_options(seed);
    old_rule.relative_tolerance = 1e-4;
    passed += props::check_policy_equivariance(leaky, Group::translation, old_rule).invariant;
  }
  CHECK(passed == 8);
}

TEST_CASE("a_binned_hand_centric_map_is_invariant_with_its_bin_edges_counted", "[property]") {
  const auto f = props::actions_of(std::make_shared<BinnedPoses>(true));
  int discontinuities = 0;
  for (Group group : props::all_groups()) {
    props::CheckOptions options = props::eye_in_hand_options();
    options.cases = 200;
    const props::Verdict verdict = props::check_invariance(f, Component::actions, group, options);
    INFO(props::to_string(group) << ": "
                                 << (verdict.witness ? props::format_witness(*verdict.witness)
                                                     : verdict.note));
    CHECK(verdict.invariant);
    CHECK(verdict.discontinuities < verdict.cases);
    discontinuities += verdict.discontinuities;
    if (verdict.discontinuities > 0) CHECK_THAT(verdict.note, Catch::Contains("bin edge"));
  }
  CHECK(discontinuities > 0);  // the edge at 0 was met, and not called symmetry breaking
}

// In law too: the in-distribution cases, the extra ones (the pointwise witness) included, are
// moved off the case as the pointwise ones are, so a bin edge there is a discontinuity, not a NO.
// Without the move (the planted fault) the law's cells fail on the edge at 0.
TEST_CASE("a_binned_hand_centric_map_is_invariant_in_law_too_and_without_the_off_case_look_not",
          "[property]") {
  const auto binned = std::make_shared<BinnedPoses>(true);
  props::ClassifierOptions options;
  options.views = {props::View::eye_in_hand};
  options.check.cases = 200;
  options.injectivity = false;  // it does not decode
  int in_law = 0;
  for (const props::Verdict& verdict : props::classify_representation(binned, options).verdicts) {
    INFO(props::to_string(verdict.component)
         << " " << props::to_string(verdict.group) << " " << props::to_string(verdict.mode) << ": "
         << (verdict.witness ? props::format_witness(*verdict.witness) : verdict.note));
    CHECK(verdict.invariant);
    in_law += verdict.mode == props::Mode::distribution ? 1 : 0;
  }
  CHECK(in_law == 2 * static_cast<int>(props::all_groups().size()));  // flow input and target
  options.check.off_case_draws = 0;
  int failed_in_law = 0;
  for (const props::Verdict& verdict : props::classify_representation(binned, options).verdicts)
    failed_in_law += verdict.mode == props::Mode::distribution && !verdict.invariant ? 1 : 0;
  CHECK(failed_in_law > 0);
}

TEST_CASE("mutant_without_the_off_case_look_a_bin_edge_is_reported_as_symmetry_breaking",
          "[property]") {
  // Decided on the floor and the measured rounding alone, the edge at 0 fails the binned map.
  const auto f = props::actions_of(std::make_shared<BinnedPoses>(true));
  props::CheckOptions options = props::eye_in_hand_options();
  options.cases = 200;
  options.off_case_draws = 0;
  const props::Verdict verdict =
      props::check_invariance(f, Component::actions, Group::se3, options);
  CHECK_FALSE(verdict.invariant);
}

TEST_CASE("bins_in_the_world_frame_fail_with_a_witness_away_from_any_bin_edge", "[property]") {
  const auto representation = std::make_shared<BinnedPoses>(false);
  const auto f = props::actions_of(representation);
  for (Group group : {Group::translation, Group::se3}) {
    props::CheckOptions options = props::eye_in_hand_options();
    options.cases = 200;
    const props::Verdict verdict = props::check_invariance(f, Component::actions, group, options);
    REQUIRE_FALSE(verdict.invariant);
    REQUIRE(verdict.witness.has_value());
    const props::Witness& w = *verdict.witness;
    CHECK(w.off_case);
    CHECK(props::recompute_error(f, w) == w.error);
    // Away from any edge: rounding-level moves of either scene change no bin.
    std::mt19937_64 rng(11);
    for (int i = 0; i < 8; ++i) {
      CHECK(f(props::rounding_perturbation(w.scene, props::kFloat64UnitRoundoff, rng)) ==
            f(w.scene));
      const Scene moved = w.g * w.scene;
      CHECK(f(props::rounding_perturbation(moved, props::kFloat64UnitRoundoff, rng)) == f(moved));
    }
  }
}

TEST_CASE("a_check_without_a_far_case_is_an_error_not_a_verdict", "[unit]") {
  // One case of c8 is its identity on one seed in eight: that case shows nothing, and the check
  // says so instead of a verdict; on the other seeds the one far case is the verdict's.
  const auto f = props::actions_of(std::make_shared<HandCentricRepresentation>());
  props::CheckOptions options = props::eye_in_hand_options();
  options.cases = 1;
  int refused = 0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    options.seed = seed;
    INFO("seed " << seed);
    try {
      const props::Verdict one = props::check_invariance(f, Component::actions, Group::c8, options);
      CHECK(one.cases == 1);
      CHECK(one.near_identity_cases == 0);
    } catch (const Error& e) {
      CHECK_THAT(e.what(), Catch::Contains("near the identity") && Catch::Contains("more cases"));
      ++refused;
    }
  }
  CHECK(refused >= 1);
  options.seed = 1;
  options.cases = 20;
  const props::Verdict verdict = props::check_invariance(f, Component::actions, Group::c8, options);
  CHECK(verdict.invariant);
  CHECK(verdict.cases >= 1);
}

TEST_CASE("any_exception_of_the_function_under_test_stops_the_check_and_is_rethrown", "[unit]") {
  // A Python callable that cannot build its NumPy arrays raises something that is no
  // handcentric::Error; it must surface, never count as a counterexample.
  int calls = 0;
  const props::SceneFunction missing_module = [&calls](const Scene&) -> Eigen::VectorXd {
    ++calls;
    throw std::runtime_error("planted: No module named 'numpy'");
  };
  props::CheckOptions options = props::eye_in_hand_options();
  options.cases = 100000;
  CHECK_THROWS_WITH(
      props::check_invariance(missing_module, Component::actions, Group::se3, options),
      Catch::Contains("numpy"));
  CHECK(calls == 1);
}

TEST_CASE("a_map_on_a_bin_edge_by_construction_fails_and_its_witness_says_so", "[property]") {
  // The Euler angles of T_0^{-1} T_0 (the identity, up to rounding) binned at 5 degrees: every
  // scene sits on the edge at 0, so no move off the case leaves it. The NO stands, and the
  // witness says it cannot tell that from an output decided by rounding.
  const props::SceneFunction on_edge = [](const Scene& scene) -> Eigen::VectorXd {
    const RigidTransform& T0 = scene.world_T_hand0();
    const Eigen::Vector3d angles = euler(T0.inverse_compose(T0).rotation().matrix());
    return (angles / BinnedPoses::kAngleBin).array().floor().matrix();
  };
  props::CheckOptions options = props::eye_in_hand_options();
  options.cases = 200;
  const props::Verdict verdict =
      props::check_invariance(on_edge, Component::actions, Group::rotation, options);
  REQUIRE_FALSE(verdict.invariant);
  REQUIRE(verdict.witness.has_value());
  CHECK(verdict.witness->rounding_response >= verdict.witness->error);
  CHECK_THAT(props::format_witness(*verdict.witness), Catch::Contains("decided by rounding"));
  // ... and only that: not also that the difference off the case rules rounding out.
  CHECK_THAT(props::format_witness(*verdict.witness),
             !Catch::Contains("so it is no bin edge or rounding"));
}
