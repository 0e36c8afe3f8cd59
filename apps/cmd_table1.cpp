// `handcentric table1`: the paper's Table 1 (Sec. 4.2) on this library. A thin handler: the
// grid, the cache, the plan and the table live in experiments/ (table1.hpp).
//
//   handcentric table1 --out t1                 # all 28 cells, both cores, then the table
//   handcentric table1 --out t1 --resume        # after a kill: only what is missing
//   handcentric table1 --out t1 --plan          # t1/jobs.txt, one shell line per cell
//   handcentric table1 --collect t1             # the table from whatever results t1 holds
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "difficulty_options.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/experiments/table1.hpp"

namespace handcentric::apps {
namespace {

// A list as its flag spells it, "5,10,20": the library's defaults (Table1Options), which the
// flags show and parse back.
template <class Value, class Text>
std::string comma_list(const std::vector<Value>& values, Text text) {
  std::string out;
  for (const Value& v : values) out += (out.empty() ? "" : ",") + text(v);
  return out;
}

struct Table1CommandOptions {
  std::string demos =
      comma_list(experiments::Table1Options{}.demo_counts, [](int n) { return std::to_string(n); });
  std::string methods = comma_list(experiments::Table1Options{}.methods,
                                   [](const experiments::Method& m) { return m.name; });
  std::string heads =
      comma_list(experiments::Table1Options{}.heads, [](const std::string& h) { return h; });
  std::string train_seeds = comma_list(experiments::Table1Options{}.train_seeds,
                                       [](std::uint64_t seed) { return std::to_string(seed); });
  std::string protocol = "library";
  bool recipe_flags = false;  ///< --no-mirror or --perturbed-copies given
  experiments::Table1Options table;
  bool plan = false;
  std::string collect;
};

std::string this_executable() {
  std::error_code error;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::string("handcentric") : self.string();
}

int run_table1_command(Table1CommandOptions options) {
  if (!options.collect.empty()) {
    std::cout << experiments::collect_table1(options.collect);
    return 0;
  }
  experiments::Table1Options& table = options.table;
  if (experiments::parse_protocol(options.protocol) == experiments::Protocol::paper) {
    if (options.recipe_flags) {
      throw InvalidArgument(
          "--protocol paper trains on the demos alone: drop --no-mirror and --perturbed-copies, "
          "or use them with --protocol library");
    }
    table.data = experiments::training_data(experiments::Protocol::paper);
  }
  table.demo_counts = experiments::parse_int_list(options.demos, "--demos");
  table.methods = experiments::parse_methods(options.methods);
  table.heads = experiments::parse_heads(options.heads);
  table.train_seeds = experiments::parse_seed_list(options.train_seeds, "--train-seeds");
  const experiments::Table1Grid grid = experiments::prepare_table1(table);
  if (options.plan) {
    const int jobs = experiments::write_plan(grid, table.eval, this_executable());
    std::cout << "wrote " << jobs << " jobs to " << grid.dir
              << "/jobs.txt; run them (e.g. parallel -j 2 < " << grid.dir
              << "/jobs.txt), then: handcentric table1 --collect " << grid.dir << "\n";
    return 0;
  }
  experiments::run_table1(table, grid);
  std::cout << experiments::collect_table1(grid.dir);
  std::cout << "\nwrote " << grid.dir << "/table1.json, table1.md, table1.png, table1.svg\n";
  return 0;
}

}  // namespace

void add_table1_command(CLI::App& app, int& exit_code) {
  auto options = std::make_shared<Table1CommandOptions>();
  experiments::Table1Options& t = options->table;
  CLI::App* cmd = app.add_subcommand(
      "table1", "the paper's Table 1: train and score every cell, print the table");
  cmd->add_option("--demos", options->demos,
                  "numbers of demos (nested: the first N of one demo file)")
      ->capture_default_str();
  cmd->add_option("--trials", t.eval.trials, "rollouts per cell and scene set")
      ->capture_default_str();
  cmd->add_option("--audit-cases", t.eval.audit_cases,
                  "cases per group of each model's pointwise audit (the audited symmetry column; "
                  "0: no audit)")
      ->capture_default_str();
  cmd->add_option("--methods", options->methods,
                  "hand_centric, relative, absolute, c8_centre, c8_base, c8_averaged (the "
                  "default); also c8flow_centre, c8flow_averaged")
      ->capture_default_str();
  cmd->add_option("--heads", options->heads,
                  "flow, ddpm, cvae (c8_centre and c8_base use c8ddpm, c8_averaged c8ddpm_avg, "
                  "c8flow_centre c8flow_planar, c8flow_averaged c8flow_avg)")
      ->capture_default_str();
  cmd->add_option("--seed", t.demo_seed, "seed of the demos")->capture_default_str();
  cmd->add_option("--train-seeds", options->train_seeds, "training seeds, one row each")
      ->capture_default_str();
  cmd->add_option("--eval-seed", t.eval.eval_seed,
                  "seed of the train-distribution and paired OOD scenes")
      ->capture_default_str();
  cmd->add_option("--ood-seed", t.eval.ood_seed, "seed of the independent OOD scenes")
      ->capture_default_str();
  add_difficulty_options(*cmd, t.difficulty);
  cmd->add_option("--steps", t.steps, "Adam steps per cell (0: the library's automatic budget)")
      ->capture_default_str();
  cmd->add_option("--jobs", t.jobs, "trainings at once (0: one per hardware thread)")
      ->capture_default_str();
  auto* out = cmd->add_option("--out", t.out, "output directory")->capture_default_str();
  cmd->add_option("--protocol", options->protocol,
                  "training data: library (demos, their mirror images, 4 recovery copies of each "
                  "sample) or paper (the demos alone)")
      ->capture_default_str();
  cmd->add_flag(
         "--no-mirror{false}", t.data.mirror,
         "train every cell on its demos only, not also on their mirror images about the hole axis")
      ->each([options](const std::string&) { options->recipe_flags = true; });
  cmd->add_option("--perturbed-copies", t.data.perturbed_copies,
                  "relabelled recovery copies of each training sample (0: none)")
      ->capture_default_str()
      ->each([options](const std::string&) { options->recipe_flags = true; });
  cmd->add_flag("--resume", t.resume, "reuse the models and results already in --out");
  auto* plan = cmd->add_flag("--plan", options->plan,
                             "write --out/jobs.txt (one shell line per cell) and stop");
  auto* collect =
      cmd->add_option("--collect", options->collect, "build the table from the results in DIR");
  cmd->add_flag("--quiet", t.quiet, "no progress display");
  collect->excludes(plan);
  collect->excludes(out);
  cmd->callback([options, &exit_code] { exit_code = run_table1_command(*options); });
}

}  // namespace handcentric::apps
