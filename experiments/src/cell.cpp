#include "handcentric/experiments/cell.hpp"

#include <algorithm>
#include <filesystem>

#include "handcentric/core/format.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/policy/trainer.hpp"
#include "handcentric/sim/rollout.hpp"

namespace handcentric::experiments {

std::string to_string(SceneSet set) {
  switch (set) {
    case SceneSet::id:
      return "id";
    case SceneSet::ood:
      return "ood";
    case SceneSet::paired:
      return "paired";
  }
  return "?";
}

sim::SceneDistribution scene_distribution(SceneSet set, const sim::Difficulty& difficulty) {
  return difficulty.apply(set == SceneSet::id ? sim::SceneDistribution::train()
                                              : sim::SceneDistribution::ood());
}

std::string Cell::describe() const {
  return method + "/" + head + ", " + std::to_string(demos) + " demos, train seed " +
         std::to_string(train_seed);
}

std::string Cell::model_path() const {
  return "models/" + hash + ".hcm";
}

std::string Cell::result_path(SceneSet set, const EvalSettings& eval) const {
  return "results/" + hash + "." + to_string(set) + "-s" + std::to_string(eval.seed(set)) + "-n" +
         std::to_string(eval.trials) + "-r" + std::to_string(sim::kRolloutRulesVersion) + ".json";
}

std::string Cell::audit_path(const EvalSettings& eval) const {
  return "results/" + hash + ".audit-pointwise-n" + std::to_string(eval.audit_cases) + ".json";
}

bool Cell::done(const EvalSettings& eval, const std::string& dir) const {
  const std::filesystem::path root = dir;
  for (const SceneSet set : kSceneSets) {
    if (!std::filesystem::exists(root / result_path(set, eval))) return false;
  }
  return eval.audit_cases == 0 || std::filesystem::exists(root / audit_path(eval));
}

std::string digest(const std::string& bytes) {
  std::uint64_t h = 1469598103934665603ull;
  for (const unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return format_hex(h, 16);
}

std::string cell_hash(const Cell& cell) {
  const std::string text =
      "handcentric table1 cell\ndemo_digest=" + cell.demo_digest +
      "\ndemos=" + std::to_string(cell.demos) + "\ntrain_seed=" + std::to_string(cell.train_seed) +
      "\n" + cell.data.to_text() + "model_format=" + std::to_string(policy::kModelFormatVersion) +
      "\n" + cell.config.to_text();
  return digest(text);
}

int automatic_steps(const sim::TrainingData& data, policy::HeadKind head, long long demo_samples) {
  return policy::training_budget(head, data.samples(demo_samples));
}

Cell make_cell(const std::string& method, const std::string& representation,
               const std::string& head, int demos, std::uint64_t train_seed, long long demo_samples,
               const std::string& demo_digest, int steps, const sim::TrainingData& data,
               std::array<double, 2> c8_centre) {
  Cell cell;
  cell.method = method;
  cell.head = head;
  cell.demos = demos;
  cell.train_seed = train_seed;
  cell.demo_digest = demo_digest;
  cell.data = data;
  cell.data.perturbation_seed = train_seed;  // as `handcentric train --seed` does
  cell.config.representation = representation;
  cell.config.head = policy::parse_head(head);
  cell.config.c8_centre_x = c8_centre[0];
  cell.config.c8_centre_y = c8_centre[1];
  if (steps > 0) cell.config.steps = steps;
  if (cell.config.steps == 0)
    cell.config.steps = automatic_steps(data, cell.config.head, demo_samples);
  cell.config.validate();
  cell.hash = cell_hash(cell);
  return cell;
}

}  // namespace handcentric::experiments
