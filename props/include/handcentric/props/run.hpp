#pragma once
// Running a RapidCheck property with a known seed, and reading its outcome (passed or the
// shrunk counterexample) instead of printing it: the base of the Catch2 glue (catch.hpp) and of
// the mutant tests, which must see a property FAIL.
//
// Seeds: RC_PARAMS="seed=S" sets S; without it, properties run with kDefaultSeed, so a test run
// is deterministic. A failure message always names its seed and how to replay it.
//
// Only RapidCheck's public API appears here: a property's arguments are drawn with
// rc::gen::arbitrary inside a property of no arguments, and the run itself happens in run.cpp.
#include <rapidcheck.h>

#include <cstdint>
#include <functional>
#include <string>
#include <tuple>
#include <type_traits>

namespace handcentric::props {

constexpr std::uint64_t kDefaultSeed = 20261121;
/// Cases per property unless RC_PARAMS sets max_success (RapidCheck's own default is 100).
constexpr int kDefaultCases = 1000;
/// The most cases an audit's check accepts (`handcentric audit --cases`, `report --cases`, the
/// Python module's cases=): a larger value is refused with an error naming it. 10^7 cases take
/// minutes per cell in C++ and hours through a Python callable (two calls per case), which is
/// past any audit a person or a CI job waits for; and the counts derived from it (cases / 100
/// in distribution, cases / 5 injectivity pairs, RapidCheck's int counters) stay far from
/// overflow.
constexpr int kMaxCases = 10'000'000;

struct PropertyOutcome {
  bool passed = false;
  std::uint64_t seed = 0;
  int cases = 0;               ///< test cases run (up to the first failure)
  std::string counterexample;  ///< printed (shrunk when a pass was expected); empty when passed
  std::string message;         ///< RapidCheck's full message plus how to replay
};

/// Seed and case count of a property run.
struct PropertyParams {
  std::uint64_t seed = kDefaultSeed;
  int cases = kDefaultCases;
};

/// RC_PARAMS's seed and max_success where it names them, else kDefaultSeed and kDefaultCases.
PropertyParams property_params();

/// Whether a failure is news (print RapidCheck's "to reproduce" line at exit, shrink the
/// counterexample) or the expected result of a planted fault (stay quiet and do not shrink: the
/// outcome carries the first failing case as drawn).
enum class Expect { pass, failure };

/// Runs a property of no arguments (it draws its values with *gen and fails with RC_ASSERT).
PropertyOutcome run_nullary_property(const std::string& description,
                                     const std::function<void()>& property,
                                     const PropertyParams& params = property_params(),
                                     Expect expect = Expect::pass);

namespace detail {

template <typename F>
struct Arguments : Arguments<decltype(&std::decay_t<F>::operator())> {};
template <typename C, typename R, typename... A>
struct Arguments<R (C::*)(A...) const> {
  using Result = R;
  using Tuple = std::tuple<std::decay_t<A>...>;
};
template <typename C, typename R, typename... A>
struct Arguments<R (C::*)(A...)> : Arguments<R (C::*)(A...) const> {};
template <typename R, typename... A>
struct Arguments<R (*)(A...)> {
  using Result = R;
  using Tuple = std::tuple<std::decay_t<A>...>;
};

// Draws each argument in order (a braced list evaluates left to right), then calls.
template <typename Testable, typename... A>
void call_with_arbitrary(Testable& testable, std::tuple<A...>*) {
  std::tuple<A...> arguments{*rc::gen::arbitrary<A>()...};
  if constexpr (std::is_same_v<decltype(std::apply(testable, arguments)), bool>) {
    RC_ASSERT(std::apply(testable, arguments));
  } else {
    std::apply(testable, arguments);
  }
}

}  // namespace detail

/// Runs `testable` (a callable whose arguments RapidCheck generates with rc::gen::arbitrary;
/// it may return bool or assert with RC_ASSERT) under `params`.
template <typename Testable>
PropertyOutcome run_property(const std::string& description, Testable&& testable,
                             const PropertyParams& params = property_params(),
                             Expect expect = Expect::pass) {
  using Tuple = typename detail::Arguments<Testable>::Tuple;
  return run_nullary_property(
      description,
      [&testable] { detail::call_with_arbitrary(testable, static_cast<Tuple*>(nullptr)); }, params,
      expect);
}

}  // namespace handcentric::props
