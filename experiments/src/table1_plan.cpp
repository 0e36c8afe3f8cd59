// Table 1 as a plan: one shell line per unfinished cell, for GNU parallel or a Slurm array.
#include "handcentric/experiments/table1.hpp"

#include <filesystem>

#include "handcentric/core/atomic_file.hpp"
#include "handcentric/core/format.hpp"

namespace handcentric::experiments {
namespace fs = std::filesystem;
namespace {

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

}  // namespace

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
    if (cell.done(eval, grid.dir)) continue;
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

}  // namespace handcentric::experiments
