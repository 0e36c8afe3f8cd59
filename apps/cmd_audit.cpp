// `handcentric audit`: which global transforms leave each representation's actions,
// observation, flow input and flow target invariant, pointwise and in distribution, with a
// shrunk witness for every cell that fails (docs/AUDIT.md).
//
//   handcentric audit                               every built-in and ActionFlow's target
//   handcentric audit --repr hand_centric --group se3 --cases 5000 --seed 7
//   handcentric audit --exec 'python3 examples/python_representation/repr.py' --json
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/props/audit.hpp"
#include "handcentric/props/pipe_representation.hpp"

namespace handcentric::apps {
namespace {

struct AuditCommandOptions {
  std::vector<std::string> representations;
  std::string group = "all";
  int cases = props::kDefaultCases;
  std::uint64_t seed = 1;
  double timeout = 10.0;
  bool json = false;
  std::string exec;
};

std::vector<props::Group> parse_groups(const std::string& name) {
  if (name == "all") return props::all_groups();
  return {props::parse_group(name)};  // throws InvalidArgument naming the valid names
}

int run_audit(const AuditCommandOptions& options) {
  props::AuditOptions audit;
  audit.groups = parse_groups(options.group);
  audit.cases = options.cases;
  audit.seed = options.seed;
  std::vector<props::Classification> results;
  if (!options.exec.empty()) {
    auto plugin = std::make_shared<props::PipeRepresentation>(options.exec, options.timeout);
    props::ClassifierOptions classifier = props::classifier_options(audit);
    classifier.observation = plugin->provides_observation();
    results.push_back(props::classify_representation(plugin, classifier));
  } else {
    results = props::audit_builtins(options.representations, audit);
  }
  if (options.json) {
    std::cout << props::audit_json(results);
    return 0;
  }
  const props::ClassifierOptions used = props::classifier_options(audit);
  std::cout << "handcentric audit: " << audit.cases << " (scene, g) cases per pointwise cell, "
            << used.distribution.cases << " per in-distribution cell (" << used.distribution.samples
            << " noise draws each, energy test at level " << used.distribution.family_alpha
            << " per cell); seed " << audit.seed << "\n"
            << "'yes' = invariant; the number is the largest error seen (pointwise: |f(g*s) - f(s)|_inf, "
               "in distribution: energy distance). Rules: docs/AUDIT.md\n\n";
  props::print_audit(std::cout, results, audit);
  return 0;
}

void add_audit_command(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<AuditCommandOptions>();
  CLI::App* cmd = app.add_subcommand("audit", "which global transforms each representation is invariant under, and why not");
  auto* repr = cmd->add_option("--repr", options->representations,
                               "a built-in to audit (absolute, relative, relative_diff, hand_centric, actionflow); "
                               "repeatable; default: all");
  cmd->add_option("--group", options->group, "translation|rotation|se2|se3|c8|all")->capture_default_str();
  cmd->add_option("--cases", options->cases, "cases per pointwise check (in distribution: max(10, cases/100))")
      ->capture_default_str();
  cmd->add_option("--seed", options->seed, "RapidCheck seed: the same seed gives the same cases and witnesses")
      ->capture_default_str();
  cmd->add_option("--timeout", options->timeout, "seconds to wait for each answer of an --exec plug-in")
      ->capture_default_str();
  cmd->add_flag("--json", options->json, "print the JSON document of docs/AUDIT.md instead of tables");
  cmd->add_option("--exec", options->exec,
                  "audit a representation written in any language: COMMAND speaks JSON Lines (docs/AUDIT.md)")
      ->excludes(repr);
  cmd->callback([options, &exit_code] { exit_code = run_audit(*options); });
}

const CommandRegistration audit_command("audit", add_audit_command);

}  // namespace
}  // namespace handcentric::apps
