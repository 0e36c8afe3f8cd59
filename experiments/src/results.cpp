#include "handcentric/experiments/results.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "handcentric/core/errors.hpp"

namespace handcentric::experiments {
namespace {

nlohmann::json optional_number(const std::optional<double>& value) {
  return value ? nlohmann::json(*value) : nlohmann::json(nullptr);
}

nlohmann::json optional_interval(const std::optional<Interval>& value) {
  return value ? nlohmann::json::array({value->lo, value->hi}) : nlohmann::json(nullptr);
}

}  // namespace

std::string eval_json(const sim::RolloutSummary& summary, const std::string& policy,
                      const std::string& dist, std::uint64_t seed) {
  const double n = summary.trials;
  const nlohmann::json out = {{"trials", summary.trials},
                              {"success", summary.success / n},
                              {"collision", summary.collision / n},
                              {"timeout", summary.timeout / n},
                              {"invalid", summary.invalid},
                              {"clipped", summary.clipped},
                              {"policy", policy},
                              {"dist", dist},
                              {"seed", seed}};
  return out.dump();
}

sim::RolloutSummary parse_eval_json(const std::string& text, const std::string& source) {
  try {
    const nlohmann::json j = nlohmann::json::parse(text);
    sim::RolloutSummary summary;
    summary.trials = j.at("trials").get<int>();
    if (summary.trials < 1) throw std::runtime_error("trials < 1");
    const auto count = [&](const char* key) {
      const double rate = j.at(key).get<double>();
      if (!(rate >= 0.0 && rate <= 1.0))
        throw std::runtime_error(std::string(key) + " is not a rate in [0, 1]");
      return static_cast<int>(std::lround(rate * summary.trials));
    };
    summary.success = count("success");
    summary.collision = count("collision");
    summary.timeout = count("timeout");
    summary.clipped = j.at("clipped").get<int>();
    return summary;
  } catch (const std::exception& e) {
    throw InvalidArgument("result file '" + source + "' is not `handcentric eval --json` output (" +
                          e.what() + "): delete it and run its job again");
  }
}

std::vector<SymmetryVerdict> parse_audit_json(const std::string& text, const std::string& source) {
  try {
    std::vector<SymmetryVerdict> out;
    const nlohmann::json j = nlohmann::json::parse(text);
    for (const auto& check : j.at("policies").at(0).at("checks")) {
      if (check.at("mode") != "pointwise" || check.at("view") != "eye_in_hand") continue;
      const auto& error = check.at("max_error");
      // An infinite error (a chunk that could not be compared) is written as a string.
      out.push_back(
          {check.at("group").get<std::string>(), check.at("equivariant").get<bool>(),
           error.is_number() ? error.get<double>() : std::numeric_limits<double>::infinity()});
    }
    if (out.empty()) throw std::runtime_error("no eye-in-hand pointwise check");
    return out;
  } catch (const std::exception& e) {
    throw InvalidArgument("audit file '" + source +
                          "' is not `handcentric audit --model --json` output (" + e.what() +
                          "): delete it and run its job again");
  }
}

Row collect_row(const Cell& cell, const EvalSettings& eval, const std::string& dir) {
  Row row;
  row.method = cell.method;
  row.head = cell.head;
  row.demos = cell.demos;
  row.trials = eval.trials;
  row.steps = cell.config.steps;
  row.train_seed = cell.train_seed;
  row.model = cell.hash;
  for (const SceneSet set : kSceneSets) {
    const std::filesystem::path path = std::filesystem::path(dir) / cell.result_path(set, eval);
    if (!std::filesystem::exists(path)) continue;
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    const sim::RolloutSummary summary = parse_eval_json(text.str(), path.string());
    const double rate = static_cast<double>(summary.success) / summary.trials;
    switch (set) {
      case SceneSet::id:
        row.id_success = rate;
        row.id_ci = wilson_interval(summary.success, summary.trials);
        break;
      case SceneSet::ood:
        row.ood_success = rate;
        row.ood_ci = wilson_interval(summary.success, summary.trials);
        break;
      case SceneSet::paired:
        row.ood_paired_success = rate;
        break;
    }
  }
  const std::filesystem::path audit = std::filesystem::path(dir) / cell.audit_path(eval);
  if (eval.audit_cases > 0 && std::filesystem::exists(audit)) {
    std::ifstream in(audit);
    std::stringstream text;
    text << in.rdbuf();
    row.symmetry = parse_audit_json(text.str(), audit.string());
  }
  return row;
}

std::string rows_json(const std::vector<Row>& rows) {
  nlohmann::json list = nlohmann::json::array();
  for (const Row& r : rows) {
    nlohmann::json symmetry = nullptr;
    for (const SymmetryVerdict& v : r.symmetry) {
      symmetry[v.group] = {{"equivariant", v.equivariant},
                           {"max_error", std::isfinite(v.max_error) ? nlohmann::json(v.max_error)
                                                                    : nlohmann::json("inf")}};
    }
    list.push_back({{"method", r.method},
                    {"head", r.head},
                    {"demos", r.demos},
                    {"trials", r.trials},
                    {"train_seed", r.train_seed},
                    {"steps", r.steps},
                    {"model", r.model},
                    {"id_success", optional_number(r.id_success)},
                    {"ood_success", optional_number(r.ood_success)},
                    {"ood_paired_success", optional_number(r.ood_paired_success)},
                    {"id_ci", optional_interval(r.id_ci)},
                    {"ood_ci", optional_interval(r.ood_ci)},
                    {"symmetry", symmetry}});
  }
  return nlohmann::json{{"rows", list}}.dump(2) + "\n";
}

}  // namespace handcentric::experiments
