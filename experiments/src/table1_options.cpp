// Table 1's options, checked before anything is written, and its comma-separated lists.
#include "handcentric/experiments/table1.hpp"

#include <set>

#include "handcentric/core/errors.hpp"
#include "handcentric/props/run.hpp"

namespace handcentric::experiments {

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
  for (const std::string& item : split_list(text)) {
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
  for (const std::string& item : split_list(text)) {
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

}  // namespace handcentric::experiments
