// Table 1's directory, demos and cells.json: the grid every way of running shares.
#include "handcentric/experiments/table1.hpp"

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "handcentric/core/atomic_file.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/sim/collision.hpp"
#include "handcentric/sim/demos.hpp"
#include "handcentric/sim/expert.hpp"
#include "handcentric/sim/scenes.hpp"
#include "read_file.hpp"

namespace handcentric::experiments {
namespace fs = std::filesystem;
namespace {

nlohmann::json cells_json(const Table1Grid& grid, const EvalSettings& eval,
                          std::uint64_t demo_seed) {
  nlohmann::json cells = nlohmann::json::array();
  for (const Cell& c : grid.cells) {
    cells.push_back({{"method", c.method},
                     {"head", c.head},
                     {"representation", c.config.representation},
                     {"demos", c.demos},
                     {"train_seed", c.train_seed},
                     {"steps", c.config.steps},
                     {"mirror", c.data.mirror},
                     {"perturbed_copies", c.data.perturbed_copies},
                     {"offset_cm", c.data.offset_cm},
                     {"offset_deg", c.data.offset_deg},
                     {"recovery_steps", c.data.recovery_steps},
                     {"hash", c.hash}});
  }
  return {{"format", "handcentric-table1-cells"},
          {"version", 1},
          {"demo_file", grid.demo_file},
          {"demo_seed", demo_seed},
          {"workspace_cm", grid.difficulty.workspace_cm},
          {"clearance_cm", grid.difficulty.clearance_cm},
          {"eval",
           {{"trials", eval.trials},
            {"eval_seed", eval.eval_seed},
            {"ood_seed", eval.ood_seed},
            {"audit_cases", eval.audit_cases}}},
          {"cells", cells}};
}

}  // namespace

Table1Grid prepare_table1(const Table1Options& options) {
  options.validate();
  Table1Grid grid;
  const fs::path dir = fs::absolute(options.out);
  grid.dir = dir.string();
  if (fs::exists(dir / "cells.json") && !options.resume) {
    throw InvalidArgument("--out '" + options.out +
                          "' already holds a Table 1 run (cells.json): pass --resume to finish it, "
                          "or choose another --out");
  }
  std::error_code error;
  fs::create_directories(dir / "models", error);
  fs::create_directories(dir / "results", error);
  if (error || !fs::is_directory(dir / "results")) {
    throw FileError("cannot create the directory '" + dir.string() + "' (" + error.message() +
                    "): check --out");
  }
  const int largest = *std::max_element(options.demo_counts.begin(), options.demo_counts.end());
  grid.difficulty = options.difficulty;
  // The default keeps its old name, so earlier runs resume; another difficulty gets its own file.
  grid.demo_file = "demos-seed" + std::to_string(options.demo_seed) + "-n" +
                   std::to_string(largest) +
                   (options.difficulty.is_default()
                        ? std::string()
                        : "-w" + format_shortest(options.difficulty.workspace_cm) + "-c" +
                              format_shortest(options.difficulty.clearance_cm)) +
                   ".jsonl";
  const fs::path demo_path = dir / grid.demo_file;
  if (!fs::exists(demo_path)) {
    const sim::CollisionChecker checker(options.difficulty.geometry());
    const auto scenes = sim::sample_scenes(scene_distribution(SceneSet::id, options.difficulty),
                                           largest, options.demo_seed);
    const sim::ExpertRun run = sim::expert_demos(scenes, options.demo_seed, checker);
    if (static_cast<int>(run.demos.size()) < largest) {
      throw InvalidArgument("the expert solved " + std::to_string(run.demos.size()) + " of " +
                            std::to_string(largest) + " scenes of demo seed " +
                            std::to_string(options.demo_seed) + ": choose another --seed");
    }
    sim::save_demos(demo_path.string(), run.demos, checker.geometry());
  }
  const std::string demo_bytes = read_file(demo_path);
  const std::string demo_digest = digest(demo_bytes);
  const std::vector<sim::Demo> demos = sim::load_demos(demo_path.string());
  std::vector<long long> samples_upto(demos.size() + 1,
                                      0);  // training samples of the first n demos
  for (std::size_t i = 0; i < demos.size(); ++i) {
    samples_upto[i + 1] = samples_upto[i] + static_cast<long long>(demos[i].world_T_hand.size());
  }
  for (const Method& method : options.methods) {
    const std::vector<std::string> heads =
        method.fixed_head.empty() ? options.heads : std::vector<std::string>{method.fixed_head};
    for (const std::string& head : heads) {
      for (const std::uint64_t seed : options.train_seeds) {
        for (const int n : options.demo_counts) {
          grid.cells.push_back(make_cell(method.name, method.representation, head, n, seed,
                                         samples_upto[static_cast<std::size_t>(n)], demo_digest,
                                         options.steps, options.data, method.c8_centre));
        }
      }
    }
  }
  write_file_atomically((dir / "cells.json").string(),
                        cells_json(grid, options.eval, options.demo_seed).dump(2) + "\n");
  return grid;
}

}  // namespace handcentric::experiments
