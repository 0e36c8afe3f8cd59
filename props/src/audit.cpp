#include "handcentric/props/audit.hpp"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/flow_target.hpp"
#include "handcentric/core/representations.hpp"

namespace handcentric::props {
namespace {

std::string pad(const std::string& text, std::size_t width) {
  return text.size() >= width ? text : text + std::string(width - text.size(), ' ');
}

std::string row_label(Component component, Mode mode) {
  return to_string(component) + (mode == Mode::distribution ? " (in distribution)" : "");
}

// "yes 3.1e-15" / "NO  2.0e+00": the mark and the largest error (distribution: energy distance).
std::string cell_text(const Verdict& verdict) {
  char text[40];
  std::snprintf(text, sizeof(text), "%-3s %8.1e", verdict.invariant ? "yes" : "NO", verdict.max_error);
  return text;
}

std::string indent(const std::string& text, const std::string& prefix) {
  std::istringstream lines(text);
  std::string line, out;
  while (std::getline(lines, line)) out += prefix + line + "\n";
  return out;
}

}  // namespace

std::vector<std::string> auditable_names() {
  std::vector<std::string> names = builtin_representation_names();
  names.push_back("actionflow");
  return names;
}

ClassifierOptions classifier_options(const AuditOptions& options) {
  if (options.cases < 1) {
    throw InvalidArgument("--cases must be at least 1, got " + std::to_string(options.cases));
  }
  ClassifierOptions classifier;
  classifier.groups = options.groups;
  classifier.check.cases = options.cases;
  classifier.check.seed = options.seed;
  classifier.distribution.cases = std::max(10, (options.cases + 99) / 100);
  return classifier;
}

std::vector<Classification> audit_builtins(const std::vector<std::string>& names, const AuditOptions& options) {
  const ClassifierOptions classifier = classifier_options(options);
  const std::vector<std::string> all = auditable_names();
  std::vector<Classification> out;
  for (const std::string& name : names.empty() ? all : names) {
    if (name == "actionflow") {
      out.push_back(classify_flow_target(std::make_shared<ActionFlowTarget>(), classifier));
    } else if (std::find(all.begin(), all.end(), name) != all.end()) {
      out.push_back(classify_representation(make_representation(name), classifier));
    } else {
      std::string valid;
      for (const std::string& n : all) valid += (valid.empty() ? "" : ", ") + n;
      throw InvalidArgument("unknown representation '" + name + "' for --repr; use one of " + valid +
                            " (or --exec 'COMMAND' for your own)");
    }
  }
  return out;
}

void print_audit(std::ostream& out, const std::vector<Classification>& classifications, const AuditOptions& options,
                 bool witnesses) {
  constexpr std::size_t kLabel = 30, kCell = 14;
  for (const Classification& classification : classifications) {
    out << classification.name << "\n  " << pad("component", kLabel);
    for (Group group : options.groups) out << " | " << pad(to_string(group), kCell);
    out << "\n";
    std::vector<const Verdict*> failing;
    for (Mode mode : {Mode::pointwise, Mode::distribution}) {
      for (Component component : {Component::actions, Component::observation, Component::flow_input,
                                  Component::flow_target, Component::policy}) {
        bool any = false;
        std::string row = "  " + pad(row_label(component, mode), kLabel);
        for (Group group : options.groups) {
          const Verdict* verdict = find_verdict(classification, component, mode, group);
          if (verdict == nullptr) continue;
          any = true;
          row += " | " + pad(cell_text(*verdict), kCell);
          if (!verdict->invariant && verdict->witness) failing.push_back(verdict);
        }
        if (any) out << row << "\n";
      }
    }
    if (witnesses) {
      for (const Verdict* verdict : failing) {
        out << "  witness: " << row_label(verdict->component, verdict->mode) << " under " << to_string(verdict->group)
            << " (seed " << verdict->seed << ", shrunk by RapidCheck; replay with the same --seed)\n"
            << indent(format_witness(*verdict->witness), "    ");
      }
    }
    out << "\n";
  }
}

}  // namespace handcentric::props
