#pragma once
// Running a RapidCheck property with a known seed, and reading its outcome (passed or the
// shrunk counterexample) instead of printing it: the base of the Catch2 glue (catch.hpp) and of
// the mutant tests, which must see a property FAIL.
//
// Seeds: RC_PARAMS="seed=S" sets S; without it, properties run with kDefaultSeed, so a test run
// is deterministic. A failure message always names its seed and how to replay it.
#include <rapidcheck.h>
#include <rapidcheck/detail/TestListenerAdapter.h>

#include <cstdint>
#include <sstream>
#include <string>

namespace handcentric::props {

constexpr std::uint64_t kDefaultSeed = 20261121;
/// Cases per property unless RC_PARAMS sets max_success (RapidCheck's own default is 100).
constexpr int kDefaultCases = 1000;

struct PropertyOutcome {
  bool passed = false;
  std::uint64_t seed = 0;
  int cases = 0;              ///< test cases run (up to the first failure)
  std::string counterexample;  ///< shrunk, printed; empty when passed
  std::string message;         ///< RapidCheck's full message plus how to replay
};

/// The test parameters from RC_PARAMS (max_success, max_size, ...), with kDefaultSeed and
/// kDefaultCases unless RC_PARAMS names them.
rc::detail::TestParams test_params();

/// Whether a failure is news (print RapidCheck's "to reproduce" line at exit) or the expected
/// result of a planted fault (stay quiet: the outcome carries the counterexample).
enum class Expect { pass, failure };

/// Runs `testable` (a callable whose arguments RapidCheck generates) under `params`.
template <typename Testable>
PropertyOutcome run_property(const std::string& description, Testable&& testable,
                             const rc::detail::TestParams& params = test_params(),
                             Expect expect = Expect::pass) {
  rc::detail::TestMetadata metadata;
  metadata.id = description;
  metadata.description = description;
  rc::detail::TestListenerAdapter quiet;
  const auto result =
      expect == Expect::pass
          ? rc::detail::checkTestable(std::forward<Testable>(testable), metadata, params)
          : rc::detail::checkTestable(std::forward<Testable>(testable), metadata, params, quiet);
  PropertyOutcome outcome;
  outcome.seed = params.seed;
  std::ostringstream message;
  rc::detail::printResultMessage(result, message);
  if (result.template is<rc::detail::SuccessResult>()) {
    outcome.passed = true;
    outcome.cases = result.template get<rc::detail::SuccessResult>().numSuccess;
  } else if (result.template is<rc::detail::FailureResult>()) {
    const auto& failure = result.template get<rc::detail::FailureResult>();
    outcome.cases = failure.numSuccess + 1;
    std::ostringstream example;
    for (const auto& [type, value] : failure.counterExample) example << type << ":\n" << value << "\n";
    outcome.counterexample = example.str();
  }
  message << "\nseed " << params.seed << "; replay with RC_PARAMS=\"seed=" << params.seed << "\"";
  outcome.message = message.str();
  return outcome;
}

}  // namespace handcentric::props
