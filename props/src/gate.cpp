#include "handcentric/props/gate.hpp"

#include "handcentric/core/errors.hpp"

namespace handcentric::props {
namespace {

Component parse_component(const std::string& name, const Spelling& spelling) {
  for (Component c : {Component::actions, Component::observation, Component::flow_input,
                      Component::flow_target, Component::policy}) {
    if (to_string(c) == name) return c;
  }
  throw InvalidArgument("unknown component '" + name + "' in " + spelling.option("expect") +
                        "; use actions, observation, flow_input, flow_target or policy, e.g. " +
                        spelling.with_value("expect", "actions:se3"));
}

std::string item_text(const ExpectedSymmetry& e, const Spelling& spelling) {
  return spelling.with_value(
      "expect", (e.component ? to_string(*e.component) + ":" : "") + to_string(e.group));
}

// An item nothing was checked under: say which part of it matched nothing, the component, or
// the group and view.
[[noreturn]] void refuse_unmatched(const std::vector<Classification>& results,
                                   const ExpectedSymmetry& e, const Spelling& spelling) {
  bool component_ran = !e.component.has_value();
  std::string components_ran;
  for (const Classification& c : results) {
    for (const Verdict& v : c.verdicts) {
      const std::string name = to_string(v.component);
      if (components_ran.find(name) == std::string::npos)
        components_ran += (components_ran.empty() ? "" : ", ") + name;
      if (e.component && v.component == *e.component) component_ran = true;
    }
  }
  const std::string item = item_text(e, spelling);
  if (!component_ran) {
    throw InvalidArgument(
        item + " names the component '" + to_string(*e.component) +
        "', which this audit does not check (it checks " + components_ran + "); e.g. " +
        spelling.with_value("expect", components_ran.substr(0, components_ran.find(',')) + ":" +
                                          to_string(e.group)));
  }
  throw InvalidArgument(item + " matches no check that ran; widen " +
                        (spelling.command_line ? "--group or --view" : "groups or views"));
}

}  // namespace

std::vector<ExpectedSymmetry> parse_expectations(const std::vector<std::string>& items,
                                                 const Spelling& spelling) {
  std::vector<ExpectedSymmetry> out;
  for (const std::string& item : items) {
    const std::size_t colon = item.find(':');
    ExpectedSymmetry e{std::nullopt,
                       parse_group(colon == std::string::npos ? item : item.substr(colon + 1))};
    if (colon != std::string::npos) e.component = parse_component(item.substr(0, colon), spelling);
    out.push_back(e);
  }
  return out;
}

std::vector<GateFailure> gate_failures(const std::vector<Classification>& results,
                                       const std::vector<ExpectedSymmetry>& expectations,
                                       const Spelling& spelling) {
  std::vector<GateFailure> failures;
  for (const ExpectedSymmetry& e : expectations) {
    int checked = 0;
    for (const Classification& c : results) {
      for (const Verdict& v : c.verdicts) {
        if (v.group != e.group || (e.component && v.component != *e.component)) continue;
        ++checked;
        if (!v.invariant) failures.push_back({c.name, v});
      }
    }
    if (checked == 0) refuse_unmatched(results, e, spelling);
  }
  return failures;
}

std::string gate_failure_text(const GateFailure& failure) {
  const Verdict& v = failure.verdict;
  std::string text = "expected " +
                     std::string(v.component == Component::policy ? "equivariance" : "invariance") +
                     " does not hold: " + failure.name + ", " + to_string(v.component) + " (" +
                     to_string(v.mode) + ", " + to_string(v.view) + ") under " +
                     to_string(v.group) + (v.note.empty() ? "" : "; note: " + v.note) + "\n";
  if (v.witness) text += format_witness(*v.witness) + "\n";
  return text;
}

}  // namespace handcentric::props
