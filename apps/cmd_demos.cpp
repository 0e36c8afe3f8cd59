// `handcentric demos`: expert demonstrations of the 2D insertion task (Sec. 4.2), or with
// --task insert3d of the 3D blade insertion, written to a JSON Lines file that records its task
// (format: docs/SIM.md), with the expert's discard rate on stderr (or in --json).
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "commands.hpp"
#include "difficulty_options.hpp"
#include "insert3d_options.hpp"
#include "handcentric/experiments/methods.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/sim/collision.hpp"
#include "handcentric/sim/demos.hpp"
#include "handcentric/sim/difficulty.hpp"
#include "handcentric/sim/expert.hpp"
#include "handcentric/sim/insert3d/expert.hpp"
#include "handcentric/sim/scenes.hpp"

namespace handcentric::apps {
namespace {

struct DemosOptions {
  std::string task = "peg2d";
  int n = experiments::kPaperDemoCounts.back();  ///< the paper's largest demo count
  std::string dist;
  std::string hole_angle_deg;
  std::uint64_t seed = 1;
  std::string transform;
  std::string rotate_deg;
  std::string out;
  bool json = false;
  sim::Difficulty difficulty;
};

template <typename Run>
int report(const DemosOptions& options, const std::string& dist, const Run& run) {
  const nlohmann::json summary = {{"task", options.task},
                                  {"dist", dist},
                                  {"scenes", run.scenes},
                                  {"demos", run.demos.size()},
                                  {"unsolved", run.unsolved},
                                  {"solutions", run.solutions},
                                  {"discarded", run.discarded},
                                  {"discard_rate", run.discard_rate()},
                                  {"solved_rate", run.solved_rate()},
                                  {"seed", options.seed},
                                  {"out", options.out}};
  if (options.json) {
    std::cout << summary.dump() << "\n";
  } else {
    std::cout << "wrote " << run.demos.size() << " demos of " << run.scenes << " '" << dist
              << "' scenes (task " << options.task << ") to " << options.out
              << "\nexpert: " << run.solutions << " plans, " << run.discarded
              << " invalid solutions discarded (discard rate " << run.discard_rate() << "), "
              << run.unsolved << " scenes unsolved (solved rate " << run.solved_rate() << ")\n";
  }
  return 0;
}

// The 3D blade insertion (sim/insert3d): --dist train, ood or random-se3, or --rotate-deg.
int run_insert3d_demos(const DemosOptions& options) {
  const sim::insert3d::SceneDistribution distribution = insert3d_distribution(
      options.dist, options.rotate_deg, options.hole_angle_deg, options.transform);
  const sim::insert3d::CollisionChecker checker;
  const sim::insert3d::ExpertRun run = sim::insert3d::expert_demos(
      sim::insert3d::sample_scenes(distribution, options.n, options.seed), options.seed, checker);
  sim::insert3d::save_demos(options.out, run.demos, checker.geometry());
  return report(options, distribution.name(), run);
}

int run_demos(const DemosOptions& options) {
  if (options.n < 1)
    throw InvalidArgument("--n must be at least 1, got " + std::to_string(options.n));
  if (options.task == "insert3d") {
    refuse_2d_difficulty(options.difficulty);
    return run_insert3d_demos(options);
  }
  refuse_3d_options(options.dist, options.rotate_deg);
  const sim::SceneDistribution distribution = options.difficulty.apply(
      sim::SceneDistribution::parse(options.dist.empty() ? options.hole_angle_deg : options.dist));
  auto scenes = sim::sample_scenes(distribution, options.n, options.seed);
  if (!options.transform.empty())
    scenes = sim::transform_scenes(sim::parse_planar_transform(options.transform), scenes);
  const sim::CollisionChecker checker(options.difficulty.geometry());
  const sim::ExpertRun run = sim::expert_demos(scenes, options.seed, checker);
  sim::save_demos(options.out, run.demos, checker.geometry());
  return report(options, distribution.name, run);
}

}  // namespace

void add_demos_command(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<DemosOptions>();
  CLI::App* cmd = app.add_subcommand(
      "demos",
      "expert demonstrations of the 2D peg-in-hole task or the 3D blade insertion (JSON Lines)");
  cmd->add_option("--task", options->task,
                  "peg2d (the 2D task) or insert3d (the 3D blade insertion)")
      ->check(CLI::IsMember({"peg2d", "insert3d"}))
      ->capture_default_str();
  cmd->add_option("--n", options->n, "number of scenes (one demo per solved scene)")
      ->capture_default_str();
  auto* dist = cmd->add_option("--dist", options->dist,
                               "scene distribution: train or ood (insert3d: also random-se3)")
                   ->check(CLI::IsMember({"train", "ood", "random-se3"}));
  auto* angle = cmd->add_option("--hole-angle-deg", options->hole_angle_deg,
                                "hole angles A:B in degrees (0 = opening up), instead of --dist");
  dist->excludes(angle);
  angle->excludes(dist);
  cmd->add_option(
      "--transform", options->transform,
      "apply the global planar transform DEG,X,Y (degrees about z, then cm) to every scene");
  auto* rotate = cmd->add_option(
      "--rotate-deg", options->rotate_deg,
      "insert3d: train scenes under the global rotation RX,RY,RZ (XYZ Euler, degrees)");
  rotate->excludes(dist);
  rotate->excludes(angle);
  add_difficulty_options(*cmd, options->difficulty);
  cmd->add_option("--seed", options->seed, "seed of the scenes and of the expert")
      ->capture_default_str();
  cmd->add_option("--out", options->out, "output file (written atomically)")->required();
  cmd->add_flag("--json", options->json, "print the summary as one JSON object");
  cmd->callback([options, &exit_code, cmd] {
    if (options->dist.empty() && options->hole_angle_deg.empty() && options->rotate_deg.empty()) {
      throw CLI::RequiredError("--dist, --hole-angle-deg or --rotate-deg");
    }
    (void)cmd;
    exit_code = run_demos(*options);
  });
}

}  // namespace handcentric::apps
