// Table 1 from whatever result files a run directory holds: table1.json, .md, .png and .svg.
#include "handcentric/experiments/table1.hpp"

#include <filesystem>
#include <nlohmann/json.hpp>

#include "handcentric/core/atomic_file.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/experiments/plot.hpp"
#include "read_file.hpp"

namespace handcentric::experiments {
namespace fs = std::filesystem;

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
    const nlohmann::json j = nlohmann::json::parse(read_file(cells_path));
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

}  // namespace handcentric::experiments
