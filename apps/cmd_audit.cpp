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
#include "handcentric/core/flow_target.hpp"
#include "handcentric/props/audit.hpp"
#include "handcentric/props/pipe_representation.hpp"

namespace handcentric::apps {
namespace {

struct AuditCommandOptions {
  std::vector<std::string> representations;
  std::string group = "all";
  std::string view = "all";
  int cases = props::kDefaultCases;
  std::uint64_t seed = 1;
  double timeout = 10.0;
  double tolerance = 0.0;
  std::string precision = "float64";
  bool json = false;
  std::string exec;
  std::vector<std::string> extra_poses, scalars;
};

std::vector<props::Group> parse_groups(const std::string& name) {
  if (name == "all") return props::all_groups();
  return {props::parse_group(name)};  // throws InvalidArgument naming the valid names
}

std::vector<props::View> parse_views(const std::string& name) {
  if (name == "all") return {props::View::eye_in_hand, props::View::third_person};
  if (name == "eye_in_hand") return {props::View::eye_in_hand};
  if (name == "third_person") return {props::View::third_person};
  throw InvalidArgument("unknown --view '" + name + "'; use eye_in_hand, third_person or all");
}

int run_audit(const AuditCommandOptions& options) {
  props::AuditOptions audit;
  audit.groups = parse_groups(options.group);
  audit.views = parse_views(options.view);
  audit.cases = options.cases;
  audit.seed = options.seed;
  audit.precision = props::parse_precision(options.precision);
  audit.relative_tolerance = options.tolerance;
  const double relative = props::audit_relative_tolerance(audit);  // validates --tolerance
  std::vector<props::Classification> results;
  if (!options.exec.empty()) {
    auto plugin = std::make_shared<props::PipeRepresentation>(options.exec, options.timeout, options.extra_poses,
                                                              options.scalars);
    const props::PluginCapabilities& capabilities = plugin->capabilities();  // the handshake
    props::ClassifierOptions classifier = props::classifier_options(audit);
    classifier.observation = plugin->provides_observation();
    classifier.check.shape.extra_pose_names = capabilities.extra_pose_names;
    classifier.check.shape.scalar_names = capabilities.scalar_names;
    std::shared_ptr<const FlowTarget> flow;
    if (capabilities.flow) flow = std::make_shared<props::PipeFlowTarget>(plugin);
    results.push_back(props::classify_representation(plugin, classifier, flow));
  } else {
    if (!options.extra_poses.empty() || !options.scalars.empty()) {
      throw InvalidArgument("--extra-poses and --scalars are for an --exec plug-in; the built-ins read neither");
    }
    results = props::audit_builtins(options.representations, audit);
  }
  if (options.json) {
    std::cout << props::audit_json(results);
    return 0;
  }
  const props::ClassifierOptions used = props::classifier_options(audit);
  std::cout << "handcentric audit: " << audit.cases << " (scene, g) cases per pointwise cell, "
            << used.distribution.cases << " per in-distribution cell, seed " << audit.seed << "; tolerance "
            << relative << " (1 + L)" << (options.tolerance > 0.0 ? " (--tolerance)"
                                          : audit.precision == props::Precision::float32 ? " (float32 rounding)" : "")
            << "\n"
            << "'yes' = invariant; the number is the largest error seen: pointwise |f(g*s) - f(s)|_inf; in "
               "distribution, exactly for maps affine in the noise, the larger difference of the two Gaussian "
               "laws' means and covariances, else (marked ~) the energy distance of a permutation test at level "
            << used.distribution.family_alpha << " per cell. Rules: docs/AUDIT.md\n\n";
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
  cmd->add_option("--view", options->view,
                  "eye_in_hand (no world points: Theorem 1's setting), third_person (1-8 world points that "
                  "move with g) or all")
      ->capture_default_str();
  cmd->add_option("--tolerance", options->tolerance,
                  "REL in the pointwise tolerance REL * (1 + L); default 1e-9 (float64 rounding)");
  cmd->add_option("--precision", options->precision,
                  "float64, or float32 for a representation computed in float32 (REL = 1e-4)")
      ->capture_default_str();
  cmd->add_option("--timeout", options->timeout, "seconds to wait for each answer of an --exec plug-in")
      ->capture_default_str();
  cmd->add_option("--extra-poses", options->extra_poses,
                  "names of world-frame poses to send an --exec plug-in (they move with g), e.g. start,left_hand; "
                  "a plug-in can also ask for them in its hello")
      ->delimiter(',');
  cmd->add_option("--scalars", options->scalars,
                  "names of numbers to send an --exec plug-in (g leaves them alone), e.g. gripper; a plug-in can "
                  "also ask for them in its hello")
      ->delimiter(',');
  cmd->add_flag("--json", options->json, "print the JSON document of docs/AUDIT.md instead of tables");
  cmd->add_option("--exec", options->exec,
                  "audit a representation written in any language: COMMAND speaks JSON Lines (docs/AUDIT.md)")
      ->excludes(repr);
  cmd->callback([options, &exit_code] { exit_code = run_audit(*options); });
}

const CommandRegistration audit_command("audit", add_audit_command);

}  // namespace
}  // namespace handcentric::apps
