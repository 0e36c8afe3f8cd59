#include "handcentric/experiments/table1.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "handcentric/core/atomic_file.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/experiments/model_audit.hpp"
#include "handcentric/experiments/plot.hpp"
#include "handcentric/experiments/progress.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/policy/trainer.hpp"
#include "handcentric/props/run.hpp"
#include "handcentric/sim/collision.hpp"
#include "handcentric/sim/demos.hpp"
#include "handcentric/sim/expert.hpp"
#include "handcentric/sim/rollout.hpp"
#include "handcentric/sim/scenes.hpp"

namespace handcentric::experiments {
namespace fs = std::filesystem;
namespace {

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) items.push_back(item);
  return items;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError("cannot open '" + path.string() + "': check the path");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A rollout costs about as much as this many training steps (measured: 300 rollouts in ~3 s,
// 1000 steps of a 256-wide network in ~3 s on one core); only the ETA uses it.
constexpr double kStepsPerRollout = 10.0;

double cell_work(const Cell& cell, const EvalSettings& eval) {
  return cell.config.steps + 3.0 * eval.trials * kStepsPerRollout;
}

sim::SceneDistribution distribution_of(SceneSet set, const sim::Difficulty& difficulty) {
  return difficulty.apply(set == SceneSet::id ? sim::SceneDistribution::train()
                                              : sim::SceneDistribution::ood());
}

bool cell_done(const Cell& cell, const EvalSettings& eval, const fs::path& dir) {
  for (const SceneSet set : kSceneSets) {
    if (!fs::exists(dir / cell.result_path(set, eval))) return false;
  }
  return eval.audit_cases == 0 || fs::exists(dir / cell.audit_path(eval));
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
    const sim::SceneDistribution distribution = distribution_of(set, difficulty);
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

// The train options that place c8ddpm's symmetry centre (none for other heads).
std::string c8_centre_options(const policy::PolicyConfig& config) {
  if (!policy::is_c8_planar(config.head)) return "";
  // "=": a negative coordinate is the option's value, not an option of its own.
  return " --c8-centre-x=" + format_number(config.c8_centre_x) +
         " --c8-centre-y=" + format_number(config.c8_centre_y);
}

std::string shell_quote(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

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

// " value |": appends only (GCC 12 warns, falsely, on `" " + std::string&&`, -Wrestrict).
std::string cell_text(const std::string& value) {
  std::string text = " ";
  text += value;
  text += " |";
  return text;
}

std::string rate(const std::optional<double>& value) {
  if (!value) return "-";
  return format_fixed(*value, 2);
}

// `data` with the perturbation seed of `reference`: the recipe without the per-cell seed.
bool same_recipe(sim::TrainingData data, const sim::TrainingData& reference) {
  data.perturbation_seed = reference.perturbation_seed;
  return data.to_text() == reference.to_text();
}

}  // namespace

std::string to_string(Protocol protocol) {
  return protocol == Protocol::paper ? "paper" : "library";
}

Protocol parse_protocol(const std::string& text) {
  if (text == "library") return Protocol::library;
  if (text == "paper") return Protocol::paper;
  throw InvalidArgument("--protocol '" + text +
                        "' is unknown: use library (demos, mirror images, recovery copies) or "
                        "paper (the demos alone)");
}

sim::TrainingData training_data(Protocol protocol) {
  sim::TrainingData data;
  if (protocol == Protocol::paper) {
    data.mirror = false;
    data.perturbed_copies = 0;
  }
  return data;
}

std::string describe_training_data(const sim::TrainingData& data) {
  if (same_recipe(data, training_data(Protocol::paper)))
    return "the demos alone (`--protocol paper`, as the paper trains)";
  const std::string copies =
      std::to_string(data.perturbed_copies) + " perturbed recovery copies of every sample";
  if (same_recipe(data, training_data(Protocol::library))) {
    return "the demos, their mirror images about the hole axis and " + copies +
           " (`--protocol library`, this library's default)";
  }
  return std::string("the demos") + (data.mirror ? ", their mirror images" : "") + " and " +
         copies + " (offset " + format_number(data.offset_cm) + " cm, " +
         format_number(data.offset_deg) + " deg, recovery in " +
         std::to_string(data.recovery_steps) + " steps; neither protocol)";
}

void Table1Options::validate() const {
  if (demo_counts.empty())
    throw InvalidArgument("--demos is empty: give numbers of demos, e.g. 5,10,100");
  std::set<int> seen;
  for (const int n : demo_counts) {
    if (n < 1 || n > 1000)
      throw InvalidArgument("--demos: " + std::to_string(n) + " is outside 1..1000");
    if (!seen.insert(n).second)
      throw InvalidArgument("--demos: " + std::to_string(n) + " is listed twice");
  }
  if (steps < 0)
    throw InvalidArgument("--steps must be >= 0 (0: the automatic budget), got " +
                          std::to_string(steps));
  if (methods.empty()) throw InvalidArgument("--methods is empty: name at least one method");
  if (heads.empty()) throw InvalidArgument("--heads is empty: name at least one head");
  if (train_seeds.empty()) throw InvalidArgument("--train-seeds is empty: give at least one seed");
  if (eval.trials < 1)
    throw InvalidArgument("--trials must be at least 1, got " + std::to_string(eval.trials));
  if (eval.audit_cases < 0 || eval.audit_cases > props::kMaxCases) {
    throw InvalidArgument("--audit-cases must be 0 (no audit) to " +
                          std::to_string(props::kMaxCases) + ", got " +
                          std::to_string(eval.audit_cases));
  }
  if (jobs < 0)
    throw InvalidArgument("--jobs must be >= 0 (0: one per hardware thread), got " +
                          std::to_string(jobs));
  if (eval.ood_seed == eval.eval_seed) {
    throw InvalidArgument(
        "--ood-seed " + std::to_string(eval.ood_seed) +
        " equals --eval-seed: the independent OOD scenes would be the paired ones; choose another");
  }
  // Before anything is written: a bad recipe would otherwise fail only when the first cell
  // trains, after the demo file and cells.json.
  data.validate();
  difficulty.validate();
}

std::vector<int> parse_int_list(const std::string& text, const std::string& option) {
  std::vector<int> values;
  for (const std::string& item : split(text)) {
    std::size_t used = 0;
    int value = 0;
    try {
      value = std::stoi(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || value < 1) {
      throw InvalidArgument(option + " '" + text + "': '" + item +
                            "' is not a positive integer; give e.g. 5,10,100");
    }
    values.push_back(value);
  }
  if (values.empty()) throw InvalidArgument(option + " is empty: give e.g. 5,10,100");
  return values;
}

std::vector<std::uint64_t> parse_seed_list(const std::string& text, const std::string& option) {
  std::vector<std::uint64_t> values;
  for (const std::string& item : split(text)) {
    std::size_t used = 0;
    unsigned long long value = 0;
    try {
      value = std::stoull(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || item.front() == '-') {
      throw InvalidArgument(option + " '" + text + "': '" + item +
                            "' is not a non-negative integer; give e.g. 1,2,3");
    }
    values.push_back(value);
  }
  if (values.empty()) throw InvalidArgument(option + " is empty: give e.g. 1,2,3");
  return values;
}

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
    const auto scenes = sim::sample_scenes(distribution_of(SceneSet::id, options.difficulty),
                                           largest, options.demo_seed);
    const sim::ExpertRun run = sim::expert_demos(scenes, options.demo_seed, checker);
    if (static_cast<int>(run.demos.size()) < largest) {
      throw InvalidArgument("the expert solved " + std::to_string(run.demos.size()) + " of " +
                            std::to_string(largest) + " scenes of demo seed " +
                            std::to_string(options.demo_seed) + ": choose another --seed");
    }
    sim::save_demos(demo_path.string(), run.demos, checker.geometry());
  }
  const std::string demo_bytes = read_text(demo_path);
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
        const bool skipped = cell_done(*cell, options.eval, dir);
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

int write_plan(const Table1Grid& grid, const EvalSettings& eval, const std::string& cli) {
  const fs::path dir = grid.dir;
  const std::string difficulty_flags =
      grid.difficulty.is_default()
          ? std::string()
          : " --workspace " + format_shortest(grid.difficulty.workspace_cm) + " --clearance " +
                format_shortest(grid.difficulty.clearance_cm);
  std::string lines;
  int count = 0;
  for (const Cell& cell : grid.cells) {
    if (cell_done(cell, eval, dir)) continue;
    std::string line =
        "cd " + shell_quote(grid.dir) + " && { test -f " + cell.model_path() + " || " +
        shell_quote(cli) + " train --demos " + grid.demo_file + " --max-demos " +
        std::to_string(cell.demos) + " --repr " + cell.config.representation + " --head " +
        cell.head + " --steps " + std::to_string(cell.config.steps) +
        (cell.data.mirror ? "" : " --no-mirror") + " --perturbed-copies " +
        std::to_string(cell.data.perturbed_copies) + " --offset-cm " +
        format_number(cell.data.offset_cm) + " --offset-deg " +
        format_number(cell.data.offset_deg) + " --recovery-steps " +
        std::to_string(cell.data.recovery_steps) + c8_centre_options(cell.config) + " --seed " +
        std::to_string(cell.train_seed) + " --quiet --out " + cell.model_path() + " >/dev/null; }";
    for (const SceneSet set : kSceneSets) {
      const std::string result = cell.result_path(set, eval);
      line += " && { test -f " + result + " || { " + shell_quote(cli) + " eval --model " +
              cell.model_path() + " --dist " + (set == SceneSet::id ? "train" : "ood") +
              " --trials " + std::to_string(eval.trials) + difficulty_flags + " --seed " +
              std::to_string(eval.seed(set)) + " --json > " + result + ".tmp && mv " + result +
              ".tmp " + result + "; }; }";
    }
    if (eval.audit_cases > 0) {
      const std::string audit = cell.audit_path(eval);
      line += " && { test -f " + audit + " || { " + shell_quote(cli) + " audit --model " +
              cell.model_path() + " --view eye_in_hand --pointwise --cases " +
              std::to_string(eval.audit_cases) + " --json > " + audit + ".tmp && mv " + audit +
              ".tmp " + audit + "; }; }";
    }
    lines += line + "\n";
    ++count;
  }
  write_file_atomically((dir / "jobs.txt").string(), lines);
  return count;
}

std::string collect_table1(const std::string& dir_text) {
  const fs::path dir = fs::absolute(dir_text);
  const fs::path cells_path = dir / "cells.json";
  if (!fs::exists(cells_path)) {
    throw InvalidArgument(
        "'" + dir_text +
        "' holds no cells.json: give the --out of a `handcentric table1` or --plan run");
  }
  EvalSettings eval;
  sim::Difficulty difficulty;
  std::uint64_t demo_seed = 0;
  std::vector<Row> rows;
  std::string training;  // the cells' recipe when they share one
  bool one_recipe = true;
  try {
    const nlohmann::json j = nlohmann::json::parse(read_text(cells_path));
    eval.trials = j.at("eval").at("trials").get<int>();
    eval.eval_seed = j.at("eval").at("eval_seed").get<std::uint64_t>();
    eval.ood_seed = j.at("eval").at("ood_seed").get<std::uint64_t>();
    // Runs written before the audit column have no audits.
    eval.audit_cases = j.at("eval").value("audit_cases", 0);
    demo_seed = j.at("demo_seed").get<std::uint64_t>();
    // Runs written before the difficulty options ran the paper's.
    difficulty.workspace_cm = j.value("workspace_cm", difficulty.workspace_cm);
    difficulty.clearance_cm = j.value("clearance_cm", difficulty.clearance_cm);
    difficulty.validate();
    for (const auto& c : j.at("cells")) {
      Cell cell;
      cell.method = c.at("method").get<std::string>();
      cell.head = c.at("head").get<std::string>();
      cell.demos = c.at("demos").get<int>();
      cell.train_seed = c.at("train_seed").get<std::uint64_t>();
      cell.config.steps = c.at("steps").get<int>();
      // Runs written before the mirror images existed trained on the demos only.
      cell.data.mirror = c.contains("mirror") && c.at("mirror").get<bool>();
      // ... and before the perturbed copies, on none.
      cell.data.perturbed_copies = c.value("perturbed_copies", 0);
      cell.data.offset_cm = c.value("offset_cm", cell.data.offset_cm);
      cell.data.offset_deg = c.value("offset_deg", cell.data.offset_deg);
      cell.data.recovery_steps = c.value("recovery_steps", cell.data.recovery_steps);
      cell.hash = c.at("hash").get<std::string>();
      const std::string described = describe_training_data(cell.data);
      if (rows.empty()) training = described;
      one_recipe = one_recipe && described == training;
      rows.push_back(collect_row(cell, eval, dir.string()));
    }
  } catch (const nlohmann::json::exception& e) {
    throw InvalidArgument("'" + cells_path.string() + "' is damaged (" + e.what() +
                          "): run --plan or table1 again");
  }
  if (!one_recipe) training = "a recipe of its own per cell (cells.json)";
  const std::string markdown = table1_markdown(rows, eval, demo_seed, training, difficulty);
  write_file_atomically((dir / "table1.json").string(), rows_json(rows));
  write_file_atomically((dir / "table1.md").string(), markdown);
  write_table1_figure((dir / "table1").string(), rows);
  return markdown;
}

std::string table1_markdown(const std::vector<Row>& rows, const EvalSettings& eval,
                            std::uint64_t demo_seed, const std::string& training,
                            const sim::Difficulty& difficulty) {
  std::vector<int> counts;
  std::vector<std::pair<std::string, std::string>> series;  // (method, head) in row order
  std::set<std::uint64_t> seeds;
  for (const Row& r : rows) {
    if (std::find(counts.begin(), counts.end(), r.demos) == counts.end()) counts.push_back(r.demos);
    if (std::find(series.begin(), series.end(), std::make_pair(r.method, r.head)) == series.end()) {
      series.emplace_back(r.method, r.head);
    }
    seeds.insert(r.train_seed);
  }
  std::sort(counts.begin(), counts.end());
  // Mean over the training seeds that have the value.
  const auto mean = [&](const std::string& m, const std::string& h, int n,
                        auto field) -> std::optional<double> {
    double sum = 0.0;
    int k = 0;
    for (const Row& r : rows) {
      const std::optional<double> v = r.*field;
      if (r.method == m && r.head == h && r.demos == n && v) {
        sum += *v;
        ++k;
      }
    }
    return k == 0 ? std::nullopt : std::optional<double>(sum / k);
  };
  std::string header = "| policy | scenes |";
  std::string rule = "|---|---|";
  for (const int n : counts) {
    header += cell_text(std::to_string(n));
    rule += "---|";
  }
  const bool audited =
      std::any_of(rows.begin(), rows.end(), [](const Row& r) { return !r.symmetry.empty(); });
  if (audited) {
    header += " audited symmetry |";
    rule += "---|";
  }
  // The audit column of (m, h): per group, yes when every audited model of the row is
  // equivariant, with the largest error over them.
  const auto symmetry = [&](const std::string& m, const std::string& h) {
    std::vector<SymmetryVerdict> merged;
    int models = 0, with_audit = 0;
    for (const Row& r : rows) {
      if (r.method != m || r.head != h) continue;
      ++models;
      if (r.symmetry.empty()) continue;
      ++with_audit;
      for (const SymmetryVerdict& v : r.symmetry) {
        auto it = std::find_if(merged.begin(), merged.end(),
                               [&](const SymmetryVerdict& u) { return u.group == v.group; });
        if (it == merged.end()) {
          merged.push_back(v);
        } else {
          it->equivariant = it->equivariant && v.equivariant;
          it->max_error = std::max(it->max_error, v.max_error);
        }
      }
    }
    std::string text;
    for (const SymmetryVerdict& v : merged) {
      text += (text.empty() ? "" : ", ") + v.group + (v.equivariant ? " yes" : " no") + " (" +
              format_scientific(v.max_error, 1) + ")";
    }
    if (with_audit < models) {
      text += (text.empty() ? "" : "; ") + std::to_string(with_audit) + " of " +
              std::to_string(models) + " models audited";
    }
    return text;
  };
  std::string text = "# Table 1 on this library\n\n";
  text += "Success over " + std::to_string(eval.trials) +
          " closed-loop rollouts per cell (mean over " + std::to_string(seeds.size()) +
          " training seed" + (seeds.size() == 1 ? "" : "s") +
          "). Scenes: `id` = train distribution, eval seed " + std::to_string(eval.eval_seed) +
          "; `ood` = bottom-up holes, their own seed " + std::to_string(eval.ood_seed) +
          "; `ood paired` = the global transforms of the id scenes (same seed, same noise: equal "
          "to id exactly when the policy is equivariant). Demos: the first N of `demos --n 100 "
          "--dist train --seed " +
          std::to_string(demo_seed) + "`.\n\n";
  if (!difficulty.is_default()) {
    text += "Task: " + difficulty.describe() +
            " (the paper's task: workspace 100 cm, clearance 0.1 cm).\n\n";
  }
  if (!training.empty()) text += "Training data of every cell: " + training + ".\n\n";
  if (audited) {
    text +=
        "`audited symmetry`: each model's pointwise audit, eq. (4) with the same noise on both "
        "sides (`handcentric audit --model M --view eye_in_hand --pointwise`, " +
        std::to_string(eval.audit_cases) +
        " cases per group, planar scenes for the 2D task): per group yes when every model of "
        "the row is equivariant, and the largest error over them (the task's units). A "
        "`no`'s number is the error of the first failing case, and the audit draws small g "
        "first: it shows the group is broken, not by how much (`handcentric audit --profile` "
        "measures that).\n\n";
  }
  text += header + "\n" + rule + "\n";
  for (std::size_t i = 0; i < series.size(); ++i) {
    const auto& [m, h] = series[i];
    const auto paper = paper_row(m, h);
    // Rows standing in for one paper row (the C8 rows): its line once, after the last of them.
    const auto next =
        i + 1 < series.size() ? paper_row(series[i + 1].first, series[i + 1].second) : std::nullopt;
    const bool paper_follows = paper && next && next->label == paper->label;
    const std::string label = m + "/" + h;
    std::string id = "| " + label + " | id |", ood = "| " + label + " | ood |",
                paired = "| " + label + " | ood paired |";
    std::string paper_line = "| " + (paper ? paper->label : std::string("-")) + " (paper) | id |";
    for (const int n : counts) {
      id += cell_text(rate(mean(m, h, n, &Row::id_success)));
      ood += cell_text(rate(mean(m, h, n, &Row::ood_success)));
      paired += cell_text(rate(mean(m, h, n, &Row::ood_paired_success)));
      const auto* at = std::find(kPaperDemoCounts.begin(), kPaperDemoCounts.end(), n);
      paper_line += cell_text(
          paper && at != kPaperDemoCounts.end()
              ? rate(paper->success[static_cast<std::size_t>(at - kPaperDemoCounts.begin())])
              : std::string("-"));
    }
    if (audited) {
      id += cell_text(symmetry(m, h));
      ood += cell_text("");
      paired += cell_text("");
      paper_line += cell_text("");
    }
    text += id + "\n" + ood + "\n" + paired + "\n";
    if (paper && !paper_follows) {
      std::string paper_ood = "| " + paper->label + " (paper) | ood |";
      for (const int n : counts)
        paper_ood += cell_text(n == 100 ? rate(paper->ood_at_100) : std::string("-"));
      if (audited) paper_ood += cell_text("");
      text += paper_line + "\n" + paper_ood + "\n";
    }
  }
  return text;
}

}  // namespace handcentric::experiments
