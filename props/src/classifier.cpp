#include "handcentric/props/classifier.hpp"

#include <algorithm>

#include "handcentric/core/errors.hpp"

namespace handcentric::props {
namespace {

void classify_flow(const std::shared_ptr<const FlowTarget>& target, const ClassifierOptions& options,
                   Classification& out) {
  const CheckOptions& check = options.check;
  for (Group group : options.groups) {
    out.verdicts.push_back(check_invariance(flow_input_of(target, check.noise_seed, check.flow_time),
                                            Component::flow_input, group, check));
  }
  for (Group group : options.groups) {
    out.verdicts.push_back(check_invariance(flow_target_of(target, check.noise_seed, check.flow_time),
                                            Component::flow_target, group, check));
  }
  if (!options.in_distribution) return;
  for (Component component : {Component::flow_input, Component::flow_target}) {
    for (Group group : options.groups) {
      out.verdicts.push_back(check_distribution_invariance(target, component, group, check, options.distribution));
    }
  }
}

const std::vector<Group> kNone = {};
const std::vector<Group> kTranslation = {Group::translation};
const std::vector<Group> kRotations = {Group::rotation, Group::c8};

}  // namespace

Classification classify_representation(std::shared_ptr<const Representation> representation,
                                       const ClassifierOptions& options) {
  if (!representation) throw InvalidArgument("classify_representation needs a representation, got null");
  Classification out;
  out.name = representation->name();
  for (Group group : options.groups) {
    out.verdicts.push_back(check_invariance(actions_of(representation), Component::actions, group, options.check));
  }
  if (options.observation) {
    for (Group group : options.groups) {
      out.verdicts.push_back(
          check_invariance(observation_of(representation), Component::observation, group, options.check));
    }
  }
  if (options.flow) classify_flow(std::make_shared<RectifiedFlow>(representation), options, out);
  return out;
}

Classification classify_flow_target(std::shared_ptr<const FlowTarget> target, const ClassifierOptions& options) {
  if (!target) throw InvalidArgument("classify_flow_target needs a flow target, got null");
  Classification out;
  out.name = target->name();
  classify_flow(target, options, out);
  return out;
}

std::vector<Group> invariant_groups(const Classification& classification, Component component, Mode mode) {
  std::vector<Group> groups;
  for (Group group : all_groups()) {
    const Verdict* verdict = find_verdict(classification, component, mode, group);
    if (verdict != nullptr && verdict->invariant) groups.push_back(group);
  }
  return groups;
}

const Verdict* find_verdict(const Classification& classification, Component component, Mode mode, Group group) {
  for (const Verdict& verdict : classification.verdicts) {
    if (verdict.component == component && verdict.mode == mode && verdict.group == group) return &verdict;
  }
  return nullptr;
}

std::optional<std::vector<Group>> paper_expectation(const std::string& name, Component component, Mode mode) {
  if (component == Component::policy) return std::nullopt;
  if (name == "absolute") return kNone;  // App. A.1, eqs. (11), (13)
  if (name == "relative" || name == "relative_diff") {
    // App. A.2, eq. (16): the translation part forgets p~; world proprioception does not.
    if (component == Component::actions || component == Component::flow_target) return kTranslation;
    return kNone;
  }
  if (name == "hand_centric") return all_groups();  // eqs. (9), (23), (26)
  if (name == "actionflow") {
    // App. A.4, eq. (29): R_k^T (p_k - eps) changes pointwise under any g; for a rotation about
    // the origin, R~^T eps ~ N(0, I) again, so the target is invariant in distribution only.
    if (component == Component::flow_target && mode == Mode::distribution) return kRotations;
    if (component == Component::flow_input || component == Component::flow_target) return kNone;
  }
  return std::nullopt;
}

std::vector<std::string> mismatches_with_paper(const Classification& classification) {
  std::vector<std::string> lines;
  for (const Verdict& verdict : classification.verdicts) {
    const auto expected = paper_expectation(classification.name, verdict.component, verdict.mode);
    if (!expected) continue;
    const bool should = std::find(expected->begin(), expected->end(), verdict.group) != expected->end();
    if (should != verdict.invariant) {
      lines.push_back(classification.name + " " + to_string(verdict.component) + " (" + to_string(verdict.mode) +
                      ") under " + to_string(verdict.group) + ": paper says " +
                      (should ? "invariant" : "not invariant") + ", found " +
                      (verdict.invariant ? "invariant" : "not invariant"));
    }
  }
  return lines;
}

}  // namespace handcentric::props
