// `handcentric audit --profile GROUP --out DIR` (apps/audit_profile.hpp): the error against the
// transform's size, pointwise and in distribution, with the Lie derivative at the identity.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "audit_profile.hpp"
#include "handcentric/core/atomic_file.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/core/flow_target.hpp"
#include "handcentric/experiments/model_profile.hpp"
#include "handcentric/experiments/profile_plot.hpp"
#include "handcentric/props/audit.hpp"
#include "handcentric/props/checks/classifier.hpp"
#include "handcentric/props/checks/profile.hpp"
#include "handcentric/props/transport/pipe_policy.hpp"
#include "handcentric/props/transport/pipe_representation.hpp"

namespace handcentric::apps {
namespace {

std::vector<props::Profile> builtin_profiles(const ProfileCommand& command, props::Group group,
                                             const props::ProfileOptions& options) {
  std::vector<std::string> names = command.representations;
  if (names.empty()) names = props::auditable_names();
  std::vector<props::Profile> profiles;
  for (const std::string& name : names) {
    if (name == "actionflow") {
      profiles.push_back(props::profile_flow(std::make_shared<ActionFlowTarget>(),
                                             props::Component::flow_target, group, options));
      continue;
    }
    std::shared_ptr<const Representation> representation = make_representation(name);
    profiles.push_back(props::profile_function(props::actions_of(representation), name,
                                               props::Component::actions, group, options));
  }
  return profiles;
}

// A plug-in's profile is set up as its audit is (props/audit.hpp): the extra poses and scalars
// its hello asks for, and batched requests with prefetch passes when it answers batches.
std::vector<props::Profile> exec_profiles(const ProfileCommand& command,
                                          const props::AuditOptions& audit, props::Group group,
                                          props::ProfileOptions options) {
  auto plugin = std::make_shared<props::PipeRepresentation>(
      command.exec, command.timeout, std::vector<std::string>{}, std::vector<std::string>{});
  options = props::with_audit_setup(
      options, props::plugin_classifier_options(audit, plugin->capabilities()), audit.views[0]);
  const std::shared_ptr<const Representation> profiled = props::as_checked(plugin);
  std::vector<props::Profile> profiles;
  profiles.push_back(props::profile_function(props::actions_of(profiled), plugin->name(),
                                             props::Component::actions, group, options));
  if (plugin->provides_observation())
    profiles.push_back(props::profile_function(props::observation_of(profiled), plugin->name(),
                                               props::Component::observation, group, options));
  return profiles;
}

std::vector<props::Profile> policy_exec_profiles(const ProfileCommand& command,
                                                 const props::AuditOptions& audit,
                                                 props::Group group,
                                                 props::ProfileOptions options) {
  auto plugin = std::make_shared<props::PipePolicy>(
      command.policy_exec, command.timeout, std::vector<std::string>{}, std::vector<std::string>{});
  options = props::with_audit_setup(
      options, props::plugin_classifier_options(audit, plugin->capabilities()), audit.views[0]);
  return {props::profile_policy(*props::as_checked(plugin), group, options)};
}

std::vector<props::Profile> model_profiles(const ProfileCommand& command, props::Group group,
                                           const props::ProfileOptions& options) {
  return {experiments::profile_model(command.model, group, options)};
}

}  // namespace

int run_audit_profile(const ProfileCommand& command) {
  if (command.group == "all")
    throw InvalidArgument(
        "--profile all: a profile is drawn for one group; use --profile translation, rotation, "
        "se2, se3 or c8");
  const props::Group group = props::parse_group(command.group);
  // A profile is of one view: "all" (the audit's default) draws the eye-in-hand one.
  if (command.views.size() > 1)
    throw InvalidArgument("--profile draws one view; give --view eye_in_hand or third_person");
  const props::View view = props::parse_views(command.views, "view").front();
  // The audit's setup of these scenes (props/audit.hpp): its seed, for the scenes, the policy's
  // fixed noise and the laws' draws.
  props::AuditOptions audit;
  audit.groups = {group};
  audit.views = {view};
  audit.seed = command.seed;
  props::ProfileOptions options;
  options.scenes = command.scenes;
  options.sizes = command.sizes;
  options = props::with_audit_setup(options, props::classifier_options(audit), view);
  std::vector<props::Profile> profiles;
  if (!command.exec.empty()) {
    profiles = exec_profiles(command, audit, group, options);
  } else if (!command.policy_exec.empty()) {
    profiles = policy_exec_profiles(command, audit, group, options);
  } else if (!command.model.empty()) {
    profiles = model_profiles(command, group, options);
  } else {
    profiles = builtin_profiles(command, group, options);
  }
  // Both files are computed before either is written, each atomically.
  const std::string json = props::profile_json(profiles);
  const sim::Image plot = experiments::draw_profiles(profiles);
  std::error_code error;
  std::filesystem::create_directories(command.out, error);
  if (error)
    throw FileError("--out " + command.out + ": cannot create the folder (" + error.message() +
                    "); give a folder you can write");
  write_file_atomically((std::filesystem::path(command.out) / "profile.json").string(), json);
  sim::write_png((std::filesystem::path(command.out) / "profile.png").string(), plot);
  std::cout << "handcentric audit --profile " << command.group << ": " << profiles.front().scenes
            << " scenes per size, seed " << command.seed << ", sizes in "
            << props::profile_unit(group)
            << "; error / chunk scale, median (max) over the scenes (docs/AUDIT.md, Profiles)\n";
  for (const props::Profile& p : profiles) {
    std::cout << "  " << p.name << " " << props::to_string(p.component) << ": pointwise "
              << format_significant(p.points.front().pointwise.median, 2) << " at "
              << format_significant(p.points.front().size, 2) << " .. "
              << format_significant(p.points.back().pointwise.median, 2) << " at "
              << format_significant(p.points.back().size, 2);
    if (p.points.back().distribution)
      std::cout << "; in distribution (" << p.distribution_method << ") "
                << format_significant(p.points.front().distribution->median, 2) << " .. "
                << format_significant(p.points.back().distribution->median, 2);
    std::cout << "; Lie derivative " << format_significant(p.slope.median, 2) << " ("
              << format_significant(p.slope.max, 2) << ")\n";
  }
  std::cout << "wrote " << (std::filesystem::path(command.out) / "profile.json").string()
            << " and profile.png\n";
  return 0;
}

}  // namespace handcentric::apps
