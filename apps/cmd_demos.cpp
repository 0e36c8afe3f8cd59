// `handcentric demos`: expert demonstrations of the 2D insertion task (Sec. 4.2) written to a
// JSON Lines file (format: docs/SIM.md), with the expert's discard rate on stderr (or in --json).
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "commands.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/sim/collision.hpp"
#include "handcentric/sim/demos.hpp"
#include "handcentric/sim/expert.hpp"
#include "handcentric/sim/scenes.hpp"

namespace handcentric::apps {
namespace {

struct DemosOptions {
  int n = 100;
  std::string dist;
  std::string hole_angle_deg;
  std::uint64_t seed = 1;
  std::string transform;
  std::string out;
  bool json = false;
};

int run_demos(const DemosOptions& options) {
  if (options.n < 1) throw InvalidArgument("--n must be at least 1, got " + std::to_string(options.n));
  const sim::SceneDistribution distribution =
      sim::SceneDistribution::parse(options.dist.empty() ? options.hole_angle_deg : options.dist);
  auto scenes = sim::sample_scenes(distribution, options.n, options.seed);
  if (!options.transform.empty()) scenes = sim::transform_scenes(sim::parse_planar_transform(options.transform), scenes);
  const sim::CollisionChecker checker;
  const sim::ExpertRun run = sim::expert_demos(scenes, options.seed, checker);
  sim::save_demos(options.out, run.demos, checker.geometry());
  const nlohmann::json summary = {{"dist", distribution.name},     {"scenes", run.scenes},
                                  {"demos", run.demos.size()},     {"unsolved", run.unsolved},
                                  {"solutions", run.solutions},    {"discarded", run.discarded},
                                  {"discard_rate", run.discard_rate()}, {"solved_rate", run.solved_rate()},
                                  {"seed", options.seed},          {"out", options.out}};
  if (options.json) {
    std::cout << summary.dump() << "\n";
  } else {
    std::cout << "wrote " << run.demos.size() << " demos of " << run.scenes << " '" << distribution.name
              << "' scenes to " << options.out << "\nexpert: " << run.solutions << " optimizations, "
              << run.discarded << " invalid solutions discarded (discard rate " << run.discard_rate()
              << "), " << run.unsolved << " scenes unsolved (solved rate " << run.solved_rate() << ")\n";
  }
  return 0;
}

void add_demos_command(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<DemosOptions>();
  CLI::App* cmd = app.add_subcommand("demos", "expert demonstrations of the 2D peg-in-hole task (JSON Lines)");
  cmd->add_option("--n", options->n, "number of scenes (one demo per solved scene)")->capture_default_str();
  auto* dist = cmd->add_option("--dist", options->dist, "scene distribution: train or ood")
                   ->check(CLI::IsMember({"train", "ood"}));
  auto* angle = cmd->add_option("--hole-angle-deg", options->hole_angle_deg,
                                "hole angles A:B in degrees (0 = opening up), instead of --dist");
  dist->excludes(angle);
  angle->excludes(dist);
  cmd->add_option("--transform", options->transform,
                  "apply the global planar transform DEG,X,Y (degrees about z, then cm) to every scene");
  cmd->add_option("--seed", options->seed, "seed of the scenes and of the expert")->capture_default_str();
  cmd->add_option("--out", options->out, "output file (written atomically)")->required();
  cmd->add_flag("--json", options->json, "print the summary as one JSON object");
  cmd->callback([options, &exit_code, cmd] {
    if (options->dist.empty() && options->hole_angle_deg.empty()) {
      throw CLI::RequiredError("--dist or --hole-angle-deg");
    }
    (void)cmd;
    exit_code = run_demos(*options);
  });
}

const CommandRegistration demos_command("demos", add_demos_command);

}  // namespace
}  // namespace handcentric::apps
