// The gate of `handcentric audit --expect` (props/gate.hpp), on hand-made verdicts: which
// expected symmetries fail, in what order, and the errors for an item that matches nothing.
#include <catch2/catch.hpp>

#include "handcentric/core/errors.hpp"
#include "handcentric/props/gate.hpp"

using namespace handcentric;
using Catch::Matchers::Contains;
using props::Component;
using props::Group;

namespace {

props::Verdict gate_verdict(Component component, Group group, bool invariant) {
  props::Verdict v;
  v.component = component;
  v.group = group;
  v.invariant = invariant;
  return v;
}

// A representation whose actions hold under translation only and whose observation holds under
// every group checked.
std::vector<props::Classification> gate_results() {
  props::Classification c;
  c.name = "relative";
  for (Group g : {Group::translation, Group::se3}) {
    c.verdicts.push_back(gate_verdict(Component::actions, g, g == Group::translation));
    c.verdicts.push_back(gate_verdict(Component::observation, g, true));
  }
  return {c};
}

}  // namespace

TEST_CASE("gate_passes_what_holds_and_lists_each_verdict_that_does_not", "[unit]") {
  const auto results = gate_results();
  CHECK(props::gate_failures(results, props::parse_expectations({"translation"})).empty());
  CHECK(props::gate_failures(results, props::parse_expectations({"observation:se3"})).empty());
  const auto failures =
      props::gate_failures(results, props::parse_expectations({"translation", "se3"}));
  REQUIRE(failures.size() == 1);
  CHECK(failures[0].name == "relative");
  CHECK(failures[0].verdict.component == Component::actions);
  CHECK(failures[0].verdict.group == Group::se3);
  CHECK(props::gate_failure_text(failures[0]) ==
        "expected invariance does not hold: relative, actions (pointwise, eye_in_hand) under "
        "se3\n");
  props::GateFailure policy{"p", gate_verdict(Component::policy, Group::c8, false)};
  CHECK_THAT(props::gate_failure_text(policy), Contains("expected equivariance"));
}

TEST_CASE("gate_refuses_an_item_that_matches_no_check_in_the_callers_words", "[unit]") {
  const auto results = gate_results();
  CHECK_THROWS_WITH(props::gate_failures(results, props::parse_expectations({"c8"})),
                    Contains("--expect c8 matches no check that ran; widen --group or --view"));
  CHECK_THROWS_WITH(
      props::gate_failures(results, props::parse_expectations({"policy:se3"})),
      Contains("names the component 'policy'") && Contains("e.g. --expect actions:se3"));
  CHECK_THROWS_WITH(
      props::gate_failures(results, props::parse_expectations({"c8"}), props::kPythonSpelling),
      Contains("expect=\"c8\"") && Contains("widen groups or views"));
  CHECK_THROWS_AS(props::parse_expectations({"hands:se3"}), InvalidArgument);
  CHECK_THROWS_WITH(props::parse_expectations({"se4"}), Contains("unknown group 'se4'"));
}
