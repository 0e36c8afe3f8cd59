// One in-distribution case (detail::compare_laws): its three tests run cheapest first and the
// first below its level decides the case (the verdict is the one all three would give: a case
// holds only when all three do); an extra case's shared draws are all drawn before the case can
// be called "the same law" for agreeing on every draw.
#include <catch2/catch.hpp>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "checks/check_runner.hpp"
#include "handcentric/props/checks/distribution.hpp"

namespace handcentric::props {
namespace {

using detail::CaseOutcome;
using detail::NoisePair;

// tanh of the noise: no coordinate is affine in eps, so a case is decided by the tests.
Eigen::VectorXd curved(const Eigen::VectorXd& eps) {
  return eps.array().tanh().matrix();
}

// A pair that counts each side's evaluations.
struct CountedPair {
  int before_calls = 0, after_calls = 0;
  NoisePair pair(std::function<Eigen::VectorXd(const Eigen::VectorXd&)> after) {
    NoisePair p;
    p.before = [this](const Eigen::VectorXd& eps) {
      ++before_calls;
      return curved(eps);
    };
    p.after = [this, after](const Eigen::VectorXd& eps) {
      ++after_calls;
      return after(eps);
    };
    p.noise_dimension = 3;
    p.name = "a test pair";
    return p;
  }
};

constexpr double kTolerance = 1e-9;

}  // namespace

TEST_CASE("a_case_whose_paired_test_fails_runs_no_permutation_test_and_draws_no_fresh_noise",
          "[unit]") {
  // The mean moved by 0.5: the paired test sees it at once.
  CountedPair counted;
  const NoisePair pair = counted.pair(
      [](const Eigen::VectorXd& eps) -> Eigen::VectorXd { return curved(eps).array() + 0.5; });
  const CaseOutcome outcome =
      detail::compare_laws(pair, kTolerance, CheckOptions{}, DistributionOptions{});
  CHECK_FALSE(outcome.holds);
  CHECK(outcome.witness.p_value < 1e-6);
  CHECK(outcome.witness.error > 0.0);
  CHECK_THAT(outcome.witness.detail,
             Catch::Matchers::Contains("the energy and scale tests were not run"));
  // Every evaluation of the moved side is a shared draw (the unmoved side has the affinity probes
  // besides): the energy test's independent draws were never asked for. Running all three tests
  // (the planted fault) asks for as many fresh draws again.
  INFO(counted.before_calls << " evaluations before, " << counted.after_calls << " after");
  CHECK(counted.after_calls <= counted.before_calls);
}

TEST_CASE("a_case_whose_energy_test_fails_skips_the_scale_test_and_still_fails", "[unit]") {
  // Three times the spread, the same mean: the paired test keeps its level, the energy test
  // rejects.
  CountedPair counted;
  const NoisePair pair =
      counted.pair([](const Eigen::VectorXd& eps) -> Eigen::VectorXd { return 3.0 * curved(eps); });
  const CaseOutcome outcome =
      detail::compare_laws(pair, kTolerance, CheckOptions{}, DistributionOptions{});
  CHECK_FALSE(outcome.holds);
  CHECK_THAT(outcome.witness.detail, Catch::Matchers::Contains("energy test p = "));
  CHECK_THAT(outcome.witness.detail, Catch::Matchers::Contains("the scale test was not run"));
}

TEST_CASE("a_case_of_one_law_runs_all_three_tests_and_holds", "[unit]") {
  // The same law by another map (a sign flip: tanh is odd, eps symmetric), not the same values.
  CountedPair counted;
  const NoisePair pair =
      counted.pair([](const Eigen::VectorXd& eps) -> Eigen::VectorXd { return -curved(eps); });
  const CaseOutcome outcome =
      detail::compare_laws(pair, kTolerance, CheckOptions{}, DistributionOptions{});
  CHECK(outcome.holds);
  CHECK_THAT(outcome.witness.detail, Catch::Matchers::Contains("energy test p = "));
  CHECK_THAT(outcome.witness.detail, Catch::Matchers::Contains("scale test p = "));
  CHECK(counted.after_calls > counted.before_calls);  // the fresh draws were asked for
}

TEST_CASE("an_extra_case_is_one_law_only_when_all_its_shared_draws_agree", "[unit]") {
  // The two sides differ only where eps_0 is above every eps_0 the drawn case's evaluations
  // see (its affinity probes and its 32 shared draws): a drawn case finds them equal on every
  // draw, an extra case's 1024 shared draws meet the difference on about 2% of them.
  const DistributionOptions distribution;
  double highest = -std::numeric_limits<double>::infinity();
  NoisePair recorder;
  recorder.before = recorder.after = [&highest](const Eigen::VectorXd& eps) {
    highest = std::max(highest, eps(0));
    return curved(eps);
  };
  recorder.noise_dimension = 3;
  recorder.name = "the recorder";
  const CaseOutcome same = detail::compare_laws(recorder, kTolerance, CheckOptions{}, distribution);
  REQUIRE(same.holds);
  REQUIRE(same.witness.p_value == 1.0);

  NoisePair rare;
  rare.before = curved;
  rare.after = [highest](const Eigen::VectorXd& eps) {
    Eigen::VectorXd out = curved(eps);
    if (eps(0) > highest) out(1) += 1.0;
    return out;
  };
  rare.noise_dimension = 3;
  rare.name = "a pair that differs on rare draws";
  INFO("the drawn case's highest eps_0: " << highest);
  CHECK(detail::compare_laws(rare, kTolerance, CheckOptions{}, distribution).holds);
  const CaseOutcome extra = detail::compare_laws(rare, kTolerance, CheckOptions{}, distribution,
                                                 distribution.extra_case_paired_draws);
  INFO(extra.witness.detail);
  CHECK_FALSE(extra.holds);
  CHECK_THAT(extra.witness.detail, Catch::Matchers::Contains("1024 shared draws"));
}

}  // namespace handcentric::props
