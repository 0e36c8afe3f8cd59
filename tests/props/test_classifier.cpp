// The classifier on every built-in, asserted cell by cell against App. A of the paper (issue 3,
// item 4), and on a mutant whose classification must differ.
#include <catch2/catch.hpp>
#include <memory>

#include "handcentric/core/representations.hpp"
#include "handcentric/props/audit.hpp"
#include "handcentric/props/classifier.hpp"
#include "mutants.hpp"

using namespace handcentric;
using props::Component;
using props::Group;
using props::Mode;

namespace {

props::ClassifierOptions fast() {
  props::ClassifierOptions options;
  options.check.cases = 200;
  options.distribution.cases = 5;
  return options;
}

const std::vector<Group> kNone = {};
const std::vector<Group> kTranslation = {Group::translation};
const std::vector<Group> kAll = {Group::translation, Group::rotation, Group::se2, Group::se3, Group::c8};

}  // namespace

TEST_CASE("builtin_representations_are_classified_as_the_paper_says", "[property]") {
  const auto absolute = props::classify_representation(make_representation("absolute"), fast());
  for (Component c : {Component::actions, Component::observation, Component::flow_input, Component::flow_target}) {
    CHECK(props::invariant_groups(absolute, c, Mode::pointwise) == kNone);
  }
  CHECK(props::invariant_groups(absolute, Component::flow_target, Mode::distribution) == kNone);
  for (const char* name : {"relative", "relative_diff"}) {
    INFO(name);
    const auto relative = props::classify_representation(make_representation(name), fast());
    CHECK(props::invariant_groups(relative, Component::actions, Mode::pointwise) == kTranslation);
    CHECK(props::invariant_groups(relative, Component::observation, Mode::pointwise) == kNone);
    CHECK(props::invariant_groups(relative, Component::flow_target, Mode::pointwise) == kTranslation);
    CHECK(props::invariant_groups(relative, Component::flow_target, Mode::distribution) == kTranslation);
  }
  const auto hand_centric = props::classify_representation(make_representation("hand_centric"), fast());
  for (Component c : {Component::actions, Component::observation, Component::flow_input, Component::flow_target}) {
    CHECK(props::invariant_groups(hand_centric, c, Mode::pointwise) == kAll);
  }
  CHECK(props::invariant_groups(hand_centric, Component::flow_target, Mode::distribution) == kAll);
  for (const auto* classification : {&absolute, &hand_centric}) {
    CHECK(props::mismatches_with_paper(*classification).empty());
  }
}

TEST_CASE("actionflow_target_is_classified_pointwise_none_in_distribution_rotations", "[property]") {
  const auto actionflow = props::classify_flow_target(std::make_shared<ActionFlowTarget>(), fast());
  CHECK(props::invariant_groups(actionflow, Component::flow_target, Mode::pointwise) == kNone);
  CHECK(props::invariant_groups(actionflow, Component::flow_input, Mode::pointwise) == kNone);
  CHECK(props::invariant_groups(actionflow, Component::flow_target, Mode::distribution) ==
        std::vector<Group>{Group::rotation, Group::c8});
  CHECK(props::mismatches_with_paper(actionflow).empty());
}

TEST_CASE("mutant_encoder_is_classified_translation_only_and_reported_as_a_mismatch", "[property]") {
  props::Classification mutant =
      props::classify_representation(std::make_shared<test::ForgetsRotationOnTranslation>(), fast());
  CHECK(props::invariant_groups(mutant, Component::actions, Mode::pointwise) == kTranslation);
  mutant.name = "hand_centric";  // judged as if it claimed to be hand-centric
  CHECK_FALSE(props::mismatches_with_paper(mutant).empty());
}

TEST_CASE("audit_rejects_unknown_names_and_bad_case_counts", "[unit]") {
  props::AuditOptions options;
  options.cases = 10;
  CHECK_THROWS_WITH(props::audit_builtins({"hand-centric"}, options),
                    Catch::Matchers::Contains("'hand-centric'") && Catch::Matchers::Contains("hand_centric"));
  options.cases = 0;
  CHECK_THROWS_WITH(props::audit_builtins({"absolute"}, options), Catch::Matchers::Contains("--cases"));
}
