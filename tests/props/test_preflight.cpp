// The preflight of a whole policy (props/preflight.hpp): a policy that is not a function of its
// inputs as called (its own randomness, state between calls, rows coupled by the batch) gets no
// verdict that blames g. Each planted policy is the equivariant StraightPolicy below with one
// thing added; the StraightPolicy itself passes.
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <random>

#include "handcentric/props/audit.hpp"
#include "handcentric/props/checks/policy_audit.hpp"
#include "handcentric/props/checks/preflight.hpp"
#include "run_command.hpp"

using namespace handcentric;

namespace {

constexpr int kPreflightChunk = 3;

// T_k = T_0 exp(step)^k, plus a hand-frame shift R_0 d that each variant sets in shift().
class StraightPolicy : public props::NoisyPolicy {
 public:
  std::string name() const override { return "straight"; }
  Eigen::Index noise_dimension() const override { return 3; }
  std::vector<RigidTransform> act(const Scene& o, const Eigen::VectorXd& /*noise*/) const override {
    Twist step;
    step << 0.05, 0.0, 0.01, 0.0, 0.1, 0.0;
    const Eigen::Vector3d d = shift(o);
    std::vector<RigidTransform> chunk;
    RigidTransform T = o.world_T_hand0();
    for (int k = 0; k < kPreflightChunk; ++k) {
      T = T * RigidTransform::exp(step);
      chunk.push_back(RigidTransform::unchecked(
          T.rotation().matrix(), T.translation() + o.world_T_hand0().rotation().matrix() * d));
    }
    return chunk;
  }

 protected:
  virtual Eigen::Vector3d shift(const Scene& /*o*/) const { return Eigen::Vector3d::Zero(); }
};

// Draws 1 cm noise from a generator of its own at every call; says so when `tells`.
class OwnNoisePolicy final : public StraightPolicy {
 public:
  explicit OwnNoisePolicy(bool tells) : tells_(tells) {}
  std::optional<std::vector<std::string>> last_draws() const override {
    if (!tells_) return std::nullopt;
    return std::vector<std::string>{"the test's generator"};
  }

 private:
  Eigen::Vector3d shift(const Scene& /*o*/) const override {
    std::normal_distribution<double> normal;
    return 0.01 * Eigen::Vector3d(normal(rng_), normal(rng_), normal(rng_));
  }
  bool tells_;
  mutable std::mt19937_64 rng_{7};
};

// Remembers the previous call's hand position and shifts by a tenth of the step since then.
class HistoryPolicy final : public StraightPolicy {
  Eigen::Vector3d shift(const Scene& o) const override {
    const Eigen::Vector3d now = o.world_T_hand0().translation();
    const Eigen::Vector3d d =
        previous_ ? Eigen::Vector3d(0.1 * (now - *previous_)) : Eigen::Vector3d::Zero();
    previous_ = now;
    return d;
  }
  mutable std::optional<Eigen::Vector3d> previous_;
};

// Counts its calls and shifts by 1 cm per call modulo `period`: a plan replayed step by step.
class QueuePolicy final : public StraightPolicy {
 public:
  explicit QueuePolicy(int period) : period_(period) {}

 private:
  Eigen::Vector3d shift(const Scene& /*o*/) const override {
    return Eigen::Vector3d(0.01 * static_cast<double>(calls_++ % period_), 0.0, 0.0);
  }
  int period_;
  mutable int calls_ = 0;
};

// Asked in batches; `coupled` subtracts the batch's mean hand position from each row's (in the
// hand frame, so each row alone would be equivariant under a g applied to the whole batch).
class BatchPolicy final : public StraightPolicy {
 public:
  explicit BatchPolicy(bool coupled) : coupled_(coupled) {}
  bool batched() const override { return true; }
  std::vector<std::vector<RigidTransform>> act_fresh(
      const std::vector<const Scene*>& observations,
      const std::vector<const Eigen::VectorXd*>& noises) const override {
    mean_.setZero();
    if (coupled_) {
      for (const Scene* o : observations) mean_ += o->world_T_hand0().translation();
      mean_ /= static_cast<double>(observations.size());
    }
    auto out = StraightPolicy::act_fresh(observations, noises);
    mean_.setZero();
    return out;
  }

 private:
  Eigen::Vector3d shift(const Scene& o) const override {
    return coupled_ ? Eigen::Vector3d(0.01 * o.world_T_hand0().rotation().inverse().matrix() *
                                      (o.world_T_hand0().translation() - mean_))
                    : Eigen::Vector3d::Zero();
  }
  bool coupled_;
  mutable Eigen::Vector3d mean_ = Eigen::Vector3d::Zero();
};

props::PreflightOptions preflight_options() {
  props::PreflightOptions options;
  options.check.shape.min_history = options.check.shape.max_history = 1;
  return options;
}

}  // namespace

TEST_CASE("a_function_of_its_inputs_passes_the_preflight_in_a_handful_of_calls", "[unit]") {
  const props::Preflight p = props::preflight_policy(StraightPolicy(), preflight_options());
  CHECK(p.repeatable);
  CHECK(p.note.empty());
  CHECK(p.repeat_difference == 0.0);
  CHECK(p.calls == 7);
  CHECK(p.rows == 27);
  CHECK(props::preflight_policy(BatchPolicy(false), preflight_options()).repeatable);
}

TEST_CASE("own_randomness_that_the_policy_names_leaves_out_the_pointwise_verdicts_only", "[unit]") {
  const props::Preflight p = props::preflight_policy(OwnNoisePolicy(true), preflight_options());
  CHECK_FALSE(p.repeatable);
  CHECK(p.repeat_difference > 1e-3);
  CHECK(p.draws == std::vector<std::string>{"the test's generator"});
  CHECK_THAT(p.note, Catch::Contains("the test's generator") && Catch::Contains("rng=") &&
                         Catch::Contains("no pointwise verdict"));

  props::ClassifierOptions classifier;
  classifier.groups = {props::Group::se3};
  classifier.views = {props::View::eye_in_hand};
  classifier.check.cases = 20;
  classifier.distribution.cases = 3;
  const props::Classification c =
      props::classify_policy(std::make_shared<OwnNoisePolicy>(true), classifier);
  REQUIRE(c.preflight);
  REQUIRE(c.verdicts.size() == 1);
  CHECK(c.verdicts.front().mode == props::Mode::distribution);
  classifier.in_distribution = false;  // pointwise only: nothing to give
  CHECK_THROWS_AS(props::classify_policy(std::make_shared<OwnNoisePolicy>(true), classifier),
                  props::OwnRandomness);
}

TEST_CASE("answers_that_change_at_every_call_without_a_named_draw_are_no_verdict_at_all",
          "[unit]") {
  CHECK_THROWS_WITH(props::preflight_policy(OwnNoisePolicy(false), preflight_options()),
                    Catch::Contains("at every call") && Catch::Contains("cannot be seen") &&
                        Catch::Contains("action queue"));
  CHECK_THROWS_AS(props::preflight_policy(QueuePolicy(3), preflight_options()),
                  props::StatefulPolicy);
}

// Mutant seen failing: the three rows between Q and A not asked (the queues of period 4 and 2,
// in phase with the 4 rows asked at a time, pass the preflight).
TEST_CASE("state_kept_between_calls_is_an_error_naming_state_and_the_reset", "[unit]") {
  CHECK_THROWS_WITH(props::preflight_policy(HistoryPolicy(), preflight_options()),
                    Catch::Contains("previous call") && Catch::Contains("reset="));
  // A queue in phase with the 4 rows asked at a time is caught after the 3 rows between.
  CHECK_THROWS_WITH(props::preflight_policy(QueuePolicy(4), preflight_options()),
                    Catch::Contains("after other observations"));
  CHECK_THROWS_AS(props::preflight_policy(QueuePolicy(2), preflight_options()),
                  props::StatefulPolicy);
}

TEST_CASE("rows_coupled_by_their_batch_are_an_error_naming_the_batch", "[unit]") {
  CHECK_THROWS_AS(props::preflight_policy(BatchPolicy(true), preflight_options()),
                  props::BatchCoupling);
  CHECK_THROWS_WITH(props::preflight_policy(BatchPolicy(true), preflight_options()),
                    Catch::Contains("policy.eval()"));
}

TEST_CASE("a_pointwise_yes_states_the_frequency_it_would_have_found", "[unit]") {
  CHECK(props::detectable_frequency(0) == 1.0);
  CHECK(props::detectable_frequency(1) == Approx(0.99));
  CHECK(props::detectable_frequency(1000) == Approx(4.6e-3).epsilon(0.01));
  // 99%: the chance that n draws all miss a set of frequency f is 1%.
  const double f = props::detectable_frequency(200);
  CHECK(std::pow(1.0 - f, 200) == Approx(0.01));
}

// --detect / detect=: the fewest cases whose "yes" states the frequency asked for (mutant: floor
// for ceil -> 458 cases for 0.01, whose frequency is above 0.01, fails).
TEST_CASE("detect_asks_the_fewest_cases_that_state_its_frequency", "[unit]") {
  CHECK(props::cases_to_detect(0.01) == 459);
  CHECK(props::cases_to_detect(0.001) == 4603);
  CHECK(props::cases_to_detect(0.99) == 1);
  for (const double f : {0.3, 0.05, 0.01, 0.0046, 1e-4}) {
    const int n = props::cases_to_detect(f);
    CHECK(props::detectable_frequency(n) <= f);
    if (n > 1) CHECK(props::detectable_frequency(n - 1) > f);
  }
  for (const double bad : {0.0, 1.0, -0.1, std::nan(""), 1e-9}) {
    CHECK_THROWS_AS(props::cases_to_detect(bad), InvalidArgument);
    CHECK_THROWS_WITH(props::cases_to_detect(bad), Catch::Contains("--detect"));
  }
  CHECK_THROWS_WITH(props::cases_to_detect(2.0, props::kPythonSpelling),
                    Catch::StartsWith("detect=2 is not a frequency"));
}

// Over the pipe: the plug-in's own draws cannot be seen, so answers that differ at every call are
// no verdict at all; serve_policy(..., rng="numpy") seeds them alike for o and g o. The planted
// fault under rng: the same draws added in the world frame, NO under rotation.
TEST_CASE("a_plugin_that_draws_its_own_noise_is_audited_once_it_seeds_its_draws", "[unit]") {
  const std::string options = " --group rotation --view eye_in_hand --cases 40 --json";
  const auto audit = [&](const std::string& arguments) {
    return test::run_command(test::cli() + " audit --policy-exec '" +
                             test::test_plugin("policy_hand_centric.py", arguments) + "'" +
                             options);
  };
  const test::CommandResult unseeded = audit("own_noise");
  CHECK(unseeded.exit_code == 1);
  CHECK_THAT(unseeded.err, Catch::Contains("at every call") &&
                               Catch::Contains("cannot be seen here") &&
                               Catch::Contains("serve_policy(..., rng="));
  const test::CommandResult seeded = audit("own_noise --rng");
  CHECK(seeded.exit_code == 0);
  CHECK_THAT(seeded.out, !Catch::Contains("\"equivariant\": false"));
  const test::CommandResult world = audit("own_noise_world --rng");
  CHECK(world.exit_code == 0);
  CHECK_THAT(world.out, Catch::Contains("\"equivariant\": false"));
}
