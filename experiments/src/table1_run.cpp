// Table 1's cells trained and scored in this process, `jobs` trainings at once.
#include "handcentric/experiments/table1.hpp"

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

#include "handcentric/core/atomic_file.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/experiments/model_audit.hpp"
#include "handcentric/experiments/progress.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/policy/trainer.hpp"
#include "handcentric/sim/collision.hpp"
#include "handcentric/sim/demos.hpp"
#include "handcentric/sim/rollout.hpp"
#include "handcentric/sim/scenes.hpp"

namespace handcentric::experiments {
namespace fs = std::filesystem;
namespace {

// A rollout costs about as much as this many training steps (measured: 300 rollouts in ~3 s,
// 1000 steps of a 256-wide network in ~3 s on one core); only the ETA uses it.
constexpr double kStepsPerRollout = 10.0;

double cell_work(const Cell& cell, const EvalSettings& eval) {
  return cell.config.steps + 3.0 * eval.trials * kStepsPerRollout;
}

// The hash of the training a cell runs: its own, with its head replaced by the one it trains
// as (policy::trained_as), so cells that train the same bits share it.
std::string training_hash(const Cell& cell) {
  Cell trained = cell;
  trained.config.head = policy::trained_as(cell.config.head);
  trained.head = policy::to_string(trained.config.head);
  return cell_hash(trained);
}

// Loads the cell's model, or makes it from `same_training` (the model of a cell with the same
// training_hash: its weights under this cell's head), or trains it; a new model is saved.
policy::LearnedPolicy cell_model(const Cell& cell, const sim::Difficulty& difficulty,
                                 const fs::path& dir, const std::vector<sim::Demo>& demos,
                                 const policy::LearnedPolicy* same_training) {
  const fs::path model_path = dir / cell.model_path();
  if (fs::exists(model_path)) return policy::load_model(model_path.string());
  policy::LearnedPolicy model = [&] {
    if (same_training) return policy::with_head_kind(*same_training, cell.config.head);
    const auto scenes =
        sim::training_scenes(demos, cell.config.history_length, cell.config.chunk_length,
                             cell.demos, cell.data, difficulty.geometry());
    return policy::train_policy(cell.config, scenes, cell.train_seed);
  }();
  policy::save_model(model, model_path.string());
  return model;
}

// Writes each missing result file of the cell (and its audit) with the cell's `trained` model.
void evaluate_cell(const Cell& cell, const policy::LearnedPolicy& trained, const EvalSettings& eval,
                   const sim::Difficulty& difficulty, const fs::path& dir) {
  const sim::RolloutOptions rollout_options =
      sim::RolloutOptions::for_policy(trained.config().history_length, trained.config().execute);
  // one per thread: it counts its queries
  const sim::CollisionChecker checker(difficulty.geometry());
  for (const SceneSet set : kSceneSets) {
    const fs::path result = dir / cell.result_path(set, eval);
    if (fs::exists(result)) continue;
    const sim::SceneDistribution distribution = scene_distribution(set, difficulty);
    const std::uint64_t seed = eval.seed(set);
    const auto scenes = sim::sample_scenes(distribution, eval.trials, seed);
    const sim::RolloutSummary summary =
        sim::evaluate(trained, scenes, checker, seed, rollout_options);
    write_file_atomically(result.string(),
                          eval_json(summary, trained.name(), distribution.name, seed) + "\n");
  }
  // Each row's symmetry beside its success: the model file's pointwise audit.
  const fs::path audit = dir / cell.audit_path(eval);
  if (eval.audit_cases > 0 && !fs::exists(audit)) {
    write_file_atomically(
        audit.string(), table1_model_audit_json(dir.string(), cell.model_path(), eval.audit_cases));
  }
}

}  // namespace

void run_table1(const Table1Options& options, const Table1Grid& grid) {
  const fs::path dir = grid.dir;
  const std::vector<sim::Demo> demos = sim::load_demos((dir / grid.demo_file).string());
  // One job per training: the cells that train the same bits (training_hash; c8_averaged and
  // c8_centre) run in one worker, the first trains and the others take its weights.
  std::vector<std::vector<const Cell*>> order;
  std::map<std::string, std::size_t> job_of_training;
  double total_work = 0.0;
  for (const Cell& cell : grid.cells) {
    const auto [job, added] = job_of_training.emplace(training_hash(cell), order.size());
    if (added) order.emplace_back();
    order[job->second].push_back(&cell);
    total_work += cell_work(cell, options.eval) - (added ? 0.0 : cell.config.steps);
  }
  // Largest trainings first, so the last ones to finish are short and both cores stay busy.
  std::stable_sort(order.begin(), order.end(),
                   [](const std::vector<const Cell*>& a, const std::vector<const Cell*>& b) {
                     return a.front()->config.steps > b.front()->config.steps;
                   });
  const int jobs = options.jobs > 0
                       ? options.jobs
                       : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  Progress progress(static_cast<int>(grid.cells.size()), total_work, stderr, options.quiet);
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex error_mutex;
  std::string error;
  const auto worker = [&](int id) {
    while (!failed) {
      const std::size_t i = next++;
      if (i >= order.size()) return;
      const Cell& first = *order[i].front();
      // The job's trained model, made (or loaded, when its cell was done) once when needed.
      std::optional<policy::LearnedPolicy> trained;
      const auto first_model = [&]() -> const policy::LearnedPolicy& {
        if (!trained) trained.emplace(cell_model(first, grid.difficulty, dir, demos, nullptr));
        return *trained;
      };
      for (const Cell* cell : order[i]) {
        progress.start(id, cell->describe());
        const bool skipped = cell->done(options.eval, grid.dir);
        try {
          if (!skipped) {
            evaluate_cell(*cell,
                          cell == &first
                              ? first_model()
                              : cell_model(*cell, grid.difficulty, dir, demos, &first_model()),
                          options.eval, grid.difficulty, dir);
          }
        } catch (const std::exception& e) {
          const std::lock_guard lock(error_mutex);
          if (!failed.exchange(true))
            error = "Table 1 cell " + cell->describe() + " failed: " + e.what();
          return;
        }
        progress.finish(
            id, cell_work(*cell, options.eval) - (cell == &first ? 0.0 : cell->config.steps),
            skipped);
      }
    }
  };
  std::vector<std::thread> threads;
  for (int id = 0; id < std::min<int>(jobs, static_cast<int>(order.size())); ++id)
    threads.emplace_back(worker, id);
  for (std::thread& thread : threads) thread.join();
  if (failed) throw Error(error + " (finished cells are kept: rerun with --resume)");
}

}  // namespace handcentric::experiments
