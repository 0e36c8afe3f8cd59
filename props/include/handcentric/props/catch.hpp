#pragma once
// Catch2 v2 glue for downstream suites: a property that must hold, and one that must be
// falsified (a planted fault, or a representation that is not invariant).
//
//   TEST_CASE("my_repr_actions_are_translation_invariant", "[property]") {
//     handcentric::props::require_property("...", [](const handcentric::Scene& s) { ... });
//   }
#include <catch2/catch.hpp>

#include "handcentric/props/run.hpp"

namespace handcentric::props {

/// Fails the current Catch2 test, with the shrunk counterexample and the seed, unless
/// `testable` holds on every generated case.
template <typename Testable>
void require_property(const std::string& description, Testable&& testable) {
  const PropertyOutcome outcome = run_property(description, std::forward<Testable>(testable));
  INFO(description << "\n" << outcome.message);
  REQUIRE(outcome.passed);
}

/// Fails the current Catch2 test unless RapidCheck finds a counterexample to `testable`.
/// Returns the outcome, so the test can check the witness it found.
template <typename Testable>
PropertyOutcome require_falsified(const std::string& description, Testable&& testable) {
  const PropertyOutcome outcome = run_property(description, std::forward<Testable>(testable),
                                               property_params(), Expect::failure);
  INFO(description << " was expected to FAIL (planted fault), but held on " << outcome.cases
                   << " cases; seed " << outcome.seed);
  REQUIRE_FALSE(outcome.passed);
  return outcome;
}

}  // namespace handcentric::props
