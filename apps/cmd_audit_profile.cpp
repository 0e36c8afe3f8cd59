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
#include "handcentric/experiments/model_audit.hpp"
#include "handcentric/experiments/profile_plot.hpp"
#include "handcentric/policy/c8_planar.hpp"
#include "handcentric/policy/learned_policy.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/props/transport/batch.hpp"
#include "handcentric/props/checks/classifier.hpp"
#include "handcentric/props/checks/profile.hpp"
#include "handcentric/props/transport/pipe_policy.hpp"
#include "handcentric/props/transport/pipe_representation.hpp"

namespace handcentric::apps {
namespace {

std::vector<props::Profile> builtin_profiles(const ProfileCommand& command, props::Group group,
                                             const props::ProfileOptions& options) {
  std::vector<std::string> names = command.representations;
  if (names.empty()) {
    names = builtin_representation_names();
    names.push_back("actionflow");
  }
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

std::vector<props::Profile> exec_profiles(const ProfileCommand& command, props::Group group,
                                          props::ProfileOptions options) {
  auto plugin = std::make_shared<props::PipeRepresentation>(
      command.exec, command.timeout, std::vector<std::string>{}, std::vector<std::string>{});
  const props::PluginCapabilities& capabilities = plugin->capabilities();  // the handshake
  options.shape.extra_pose_names = capabilities.extra_pose_names;
  options.shape.scalar_names = capabilities.scalar_names;
  std::shared_ptr<const Representation> profiled = plugin;
  if (capabilities.batch > 0) {  // each size's scenes in batched requests (batch.hpp)
    profiled = std::make_shared<props::BatchedRepresentation>(plugin, capabilities.batch);
    options.prefetch = true;
  }
  std::vector<props::Profile> profiles;
  profiles.push_back(props::profile_function(props::actions_of(profiled), plugin->name(),
                                             props::Component::actions, group, options));
  if (plugin->provides_observation())
    profiles.push_back(props::profile_function(props::observation_of(profiled), plugin->name(),
                                               props::Component::observation, group, options));
  return profiles;
}

std::vector<props::Profile> policy_exec_profiles(const ProfileCommand& command, props::Group group,
                                                 props::ProfileOptions options) {
  auto plugin = std::make_shared<props::PipePolicy>(
      command.policy_exec, command.timeout, std::vector<std::string>{}, std::vector<std::string>{});
  const props::PluginCapabilities& capabilities = plugin->capabilities();
  options.shape.extra_pose_names = capabilities.extra_pose_names;
  options.shape.scalar_names = capabilities.scalar_names;
  std::shared_ptr<const props::NoisyPolicy> profiled = plugin;
  if (capabilities.batch > 0) {
    profiled = std::make_shared<props::BatchedPolicy>(plugin, capabilities.batch);
    options.prefetch = true;
  }
  return {props::profile_policy(*profiled, group, options)};
}

}  // namespace

props::Profile profile_model(const std::string& path, props::Group group,
                             props::ProfileOptions options) {
  auto model = std::make_shared<policy::LearnedPolicy>(policy::load_model(path));
  const policy::PolicyConfig& config = model->config();
  // A peg2d model is profiled on planar scenes, under the groups that keep them planar
  // (experiments/model_audit.hpp).
  if (experiments::model_groups(config, {group}, "all", path).empty())
    throw InvalidArgument("--profile " + props::to_string(group) + ": " + path +
                          " is a model of the 2D task (peg2d), whose scenes lie in a plane that " +
                          props::to_string(group) +
                          " tilts; profile it under translation, se2 or c8");
  // The model's own H, point counts and view (its world points or none), as `audit --model`.
  props::ClassifierOptions classifier;
  classifier.views = {props::View::eye_in_hand, props::View::third_person};
  options.shape = experiments::model_classifier_options(config, classifier).check.shape;
  // A planar C8 head is symmetric about its own centre, not the world origin.
  if (policy::is_c8_planar(config.head)) {
    const Eigen::Vector2d centre = policy::c8::centre_of(config);
    options.centre = Eigen::Vector3d(centre.x(), centre.y(), 0.0);
  }
  props::Profile profile = props::profile_policy(props::SeededPolicy(model), group, options);
  profile.name =
      "model " + std::filesystem::path(path).filename().string() + " (" + model->name() + ")";
  return profile;
}

namespace {

std::vector<props::Profile> model_profiles(const ProfileCommand& command, props::Group group,
                                           const props::ProfileOptions& options) {
  return {profile_model(command.model, group, options)};
}

}  // namespace

int run_audit_profile(const ProfileCommand& command) {
  if (command.group == "all")
    throw InvalidArgument(
        "--profile all: a profile is drawn for one group; use --profile translation, rotation, "
        "se2, se3 or c8");
  const props::Group group = props::parse_group(command.group);
  // A profile is of one view: "all" (the audit's default) draws the eye-in-hand one.
  const props::View view = props::parse_views({command.view}, "view").front();
  props::ProfileOptions options;
  options.seed = command.seed;
  options.noise_seed = command.seed;  // the policy's fixed noise and the laws' draws too
  options.scenes = command.scenes;
  options.sizes = command.sizes;
  options.shape = props::shape_for(view);
  std::vector<props::Profile> profiles;
  if (!command.exec.empty()) {
    profiles = exec_profiles(command, group, options);
  } else if (!command.policy_exec.empty()) {
    profiles = policy_exec_profiles(command, group, options);
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
