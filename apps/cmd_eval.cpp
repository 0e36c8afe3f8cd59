// `handcentric eval`: closed-loop rollouts (sim/rollout.hpp) of a policy on N seeded scenes of
// the 2D insertion task, counted as success / collision / timeout (Sec. 4.2, Table 1), and
// invalid: a trial whose policy returned a non-finite pose is a failure with its own count and a
// one-line warning on stderr naming the first such scene, so one diverging scene does not throw
// away a long evaluation; --strict stops at it with an error instead.
// Policies: --policy expert|straight|hold (no file needed), or --model FILE: a trained model
// (policy/model_file.hpp), when this build has the policy module. The 3D blade insertion
// (sim/insert3d/rollout.hpp) with an insert3d model (its file names the task) or with --task
// insert3d --policy expert; a --task that contradicts the model file is an error naming both.
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "commands.hpp"
#include "difficulty_options.hpp"
#include "task_of_files.hpp"
#include "insert3d_options.hpp"
#include "policy_source.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/experiments/cell.hpp"
#include "handcentric/experiments/results.hpp"
#include "handcentric/experiments/table2.hpp"
#include "handcentric/sim/collision.hpp"
#include "handcentric/sim/difficulty.hpp"
#include "handcentric/sim/expert_check.hpp"
#include "handcentric/sim/insert3d/rollout.hpp"
#include "handcentric/sim/policies.hpp"
#include "handcentric/sim/rollout.hpp"
#include "handcentric/sim/scenes.hpp"

namespace handcentric::apps {
namespace {

struct EvalOptions {
  std::string task;  ///< --task as given; empty: the model file's, else peg2d
  std::string model;
  std::string policy;
  std::string dist;
  std::string hole_angle_deg;
  int trials = experiments::EvalSettings{}.trials;
  std::uint64_t seed = 1;
  std::string transform;
  bool json = false;
  double noise_scale = std::numeric_limits<double>::quiet_NaN();  // NaN: the model's own
  int execute = 0;                                                // 0: the model's own
  int euler_steps = 0;                                            // 0: the model's own
  bool strict = false;
  std::string rotate_deg;
  sim::Difficulty difficulty;
};

// The 3D blade insertion: closed-loop rollouts of the expert or a 3D model on --dist
// train|ood|random-se3 or --rotate-deg scenes, counted as in 2D.
int run_insert3d_eval(const EvalOptions& options) {
  if (!options.policy.empty() && options.policy != "expert") {
    throw InvalidArgument(
        "--policy " + options.policy +
        " is a 2D scripted policy: with --task insert3d use "
        "--policy expert or --model FILE (from `handcentric train --task insert3d`)");
  }
  const sim::insert3d::SceneDistribution distribution = insert3d_distribution(
      options.dist, options.rotate_deg, options.hole_angle_deg, options.transform);
  policy::SamplingOverrides overrides;
  if (!std::isnan(options.noise_scale)) overrides.noise_scale = options.noise_scale;
  if (options.execute != 0) overrides.execute = options.execute;
  if (options.euler_steps != 0) overrides.euler_steps = options.euler_steps;
  const LoadedInsert3dPolicy loaded = load_insert3d_policy(options.model, overrides);
  const ChunkPolicy* policy = loaded.policy.get();
  const experiments::Insert3dCounts counts = experiments::evaluate_insert3d(
      *policy, distribution, options.trials, options.seed, loaded.rollout_options);
  const double n = options.trials;
  const nlohmann::json summary = {{"task", "insert3d"},
                                  {"trials", options.trials},
                                  {"success", counts.success / n},
                                  {"collision", counts.collision / n},
                                  {"timeout", counts.timeout / n},
                                  {"invalid", counts.invalid},
                                  {"clipped", counts.clipped},
                                  {"policy", policy->name()},
                                  {"dist", distribution.name()},
                                  {"seed", options.seed}};
  if (options.json) {
    std::cout << summary.dump() << "\n";
  } else {
    std::cout << "policy " << policy->name() << " on " << options.trials << " insert3d '"
              << distribution.name() << "' scenes (seed " << options.seed << "): success "
              << counts.success / n << ", collision " << counts.collision / n << ", timeout "
              << counts.timeout / n << ", invalid " << counts.invalid << "; " << counts.clipped
              << " commands clipped to the step limits\n";
  }
  return 0;
}

int run_eval(const EvalOptions& options) {
  if (options.trials < 1)
    throw InvalidArgument("--trials must be at least 1, got " + std::to_string(options.trials));
  const std::string task = resolve_task(options.task, model_task(options.model),
                                        "--model '" + options.model + "', a model");
  if (task == policy::kTaskInsert3d) {
    refuse_2d_difficulty(options.difficulty);
    return run_insert3d_eval(options);
  }
  refuse_3d_options(options.dist, options.rotate_deg);
  const sim::SceneDistribution distribution = options.difficulty.apply(
      sim::SceneDistribution::parse(options.dist.empty() ? options.hole_angle_deg : options.dist));
  policy::SamplingOverrides overrides;
  if (!std::isnan(options.noise_scale)) overrides.noise_scale = options.noise_scale;
  if (options.execute != 0) overrides.execute = options.execute;
  if (options.euler_steps != 0) overrides.euler_steps = options.euler_steps;
  const LoadedPolicy loaded = load_chunk_policy(
      options.model, options.policy.empty() ? "expert" : options.policy, overrides);
  const auto& policy = loaded.policy;
  auto scenes = sim::sample_scenes(distribution, options.trials, options.seed);
  if (!options.transform.empty())
    scenes = sim::transform_scenes(sim::parse_planar_transform(options.transform), scenes);
  const sim::CollisionChecker checker(options.difficulty.geometry());
  sim::RolloutOptions rollout_options = loaded.rollout_options;
  rollout_options.stop_on_invalid = options.strict;
  const sim::RolloutSummary summary =
      sim::evaluate(*policy, scenes, checker, options.seed, rollout_options);
  if (summary.invalid > 0) {
    std::cerr << "handcentric: warning: " << summary.invalid << " of " << summary.trials
              << " trials invalid (counted as failures): the first is scene "
              << summary.first_invalid_scene << ", " << summary.first_invalid_reason
              << "; --strict stops at the first instead\n";
  }
  if (options.json) {
    std::cout << experiments::eval_json(summary, policy->name(), distribution.name, options.seed)
              << "\n";
  } else {
    std::cout << "policy " << policy->name() << " on " << summary.trials << " '"
              << distribution.name << "' scenes (seed " << options.seed << "): success "
              << summary.success << ", collision " << summary.collision << ", timeout "
              << summary.timeout << ", invalid " << summary.invalid << "; " << summary.clipped
              << " commands clipped to the step limits\n";
  }
  return 0;
}

}  // namespace

void add_eval_command(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<EvalOptions>();
  CLI::App* cmd = app.add_subcommand(
      "eval",
      "closed-loop rollouts of a policy on the 2D peg-in-hole task or the 3D blade insertion");
  cmd->add_option("--task", options->task,
                  "peg2d (the 2D task) or insert3d (the 3D blade insertion: --policy expert or an "
                  "insert3d --model); default: the task the --model file records, else peg2d")
      ->check(CLI::IsMember({"peg2d", "insert3d"}));
  auto* model =
      cmd->add_option("--model", options->model, "a trained model file (from `handcentric train`)");
  auto* policy = cmd->add_option("--policy", options->policy,
                                 "a policy without a file: expert, straight, hold")
                     ->check(CLI::IsMember(sim::scripted_policy_names()));
  model->excludes(policy);
  policy->excludes(model);
  auto* dist = cmd->add_option("--dist", options->dist,
                               "scene distribution: train or ood (insert3d: also random-se3)")
                   ->check(CLI::IsMember({"train", "ood", "random-se3"}));
  auto* angle = cmd->add_option("--hole-angle-deg", options->hole_angle_deg,
                                "hole angles A:B in degrees, instead of --dist");
  dist->excludes(angle);
  angle->excludes(dist);
  auto* rotate = cmd->add_option(
      "--rotate-deg", options->rotate_deg,
      "insert3d: train scenes under the global rotation RX,RY,RZ (XYZ Euler, degrees)");
  rotate->excludes(dist);
  rotate->excludes(angle);
  cmd->add_option("--trials", options->trials, "number of scenes (one rollout each)")
      ->capture_default_str();
  cmd->add_option(
      "--transform", options->transform,
      "apply the global planar transform DEG,X,Y (degrees about z, then cm) to every scene");
  add_difficulty_options(*cmd, options->difficulty);
  cmd->add_option("--seed", options->seed, "seed of the scenes and of the policy's noise")
      ->capture_default_str();
  cmd->add_option("--noise-scale", options->noise_scale,
                  "a model's sampler noise instead of its own (0: the most likely chunk, eq. 6)");
  cmd->add_option("--execute", options->execute,
                  "poses of each chunk a model executes instead of its own");
  cmd->add_option("--euler-steps", options->euler_steps,
                  "a flow model's Euler steps instead of its own");
  cmd->add_flag("--json", options->json,
                "print {\"trials\": N, \"success\": rate, \"collision\": rate, \"timeout\": rate, "
                "\"invalid\": count, ...}");
  cmd->add_flag("--strict", options->strict,
                "stop with an error at the first non-finite pose from the policy (default: count "
                "the trial as invalid)");
  cmd->callback([options, &exit_code] {
    if (options->dist.empty() && options->hole_angle_deg.empty() && options->rotate_deg.empty()) {
      throw CLI::RequiredError("--dist, --hole-angle-deg or --rotate-deg");
    }
    if (options->model.empty() && options->policy.empty())
      throw CLI::RequiredError("--model or --policy");
    exit_code = run_eval(*options);
  });
}

// Main-report section: the sim's own bar (sim/expert_check.hpp) on seeded scenes.
int run_sim_section(std::ostream& out, const ReportOptions&) {
  constexpr int kScenes = sim::kExpertBarScenes;
  constexpr int kRollouts = sim::kExpertBarRollouts;
  constexpr std::uint64_t kSeed = sim::kExpertBarSeed;
  out << "sim: 2D peg-in-hole (Sec. 4.2), expert demos on " << kScenes
      << " scenes and closed-loop expert rollouts on " << kRollouts
      << " scenes per distribution, seed " << kSeed << "\n";
  int status = 0;
  for (const auto& distribution :
       {sim::SceneDistribution::train(), sim::SceneDistribution::ood()}) {
    const sim::ExpertCheck check = sim::check_expert(distribution, kScenes, kRollouts, kSeed);
    out << "  " << std::left << std::setw(5) << distribution.name << std::right << " expert solved "
        << std::setw(5) << format_fixed(100.0 * check.solved_rate, 1) << "% (discard rate "
        << format_fixed(check.discard_rate, 3) << "), closed loop " << check.rollout_success << "/"
        << check.rollouts << " success  " << (check.passes() ? "ok" : "BELOW THE 99% BAR") << "\n";
    if (!check.passes()) status = 1;
  }
  out << "  (handcentric demos / eval --policy expert reproduce these; docs/SIM.md)\n";
  return status;
}

}  // namespace handcentric::apps
