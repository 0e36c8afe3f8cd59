#include "handcentric/experiments/results_page.hpp"

#include <algorithm>

#include "handcentric/core/format.hpp"
#include "handcentric/experiments/methods.hpp"

namespace handcentric::experiments {
namespace {

// "26/30: 0.87 [0.70, 0.95]"
std::string counts_text(int successes, int trials) {
  if (trials < 1) return "-";
  const Interval interval = wilson_interval(successes, trials);
  return std::to_string(successes) + "/" + std::to_string(trials) + ": " +
         rate_text(static_cast<double>(successes) / trials, interval);
}

// "se2 yes (3.1e-15), se3 no (2.0e+00)"; "-" when not audited.
std::string symmetry_text(const std::vector<SymmetryVerdict>& verdicts) {
  std::string text;
  for (const SymmetryVerdict& v : verdicts) {
    text += (text.empty() ? "" : ", ") + v.group + (v.equivariant ? " yes" : " no") + " (" +
            format_scientific(v.max_error, 1) + ")";
  }
  return text.empty() ? "-" : text;
}

}  // namespace

std::string rate_text(const std::optional<double>& rate, const std::optional<Interval>& interval) {
  if (!rate) return "-";
  std::string text = format_fixed(*rate, 2);
  if (interval)
    text += " [" + format_fixed(interval->lo, 2) + ", " + format_fixed(interval->hi, 2) + "]";
  return text;
}

Table table1_table(const std::vector<Row>& rows, const std::string& id,
                   const std::string& caption) {
  Table table;
  table.id = id;
  table.kind = "results";
  table.caption = caption;
  const bool seeds = std::any_of(rows.begin(), rows.end(), [&](const Row& r) {
    return r.train_seed != rows.front().train_seed;
  });
  const bool audited =
      std::any_of(rows.begin(), rows.end(), [](const Row& r) { return !r.symmetry.empty(); });
  // The paper's numbers are its Table 1's, also beside Fig. 5's grid (whose flow rows they are).
  table.columns = {"method / head", "demos"};
  if (seeds) table.columns.push_back("training seed");
  table.columns.insert(table.columns.end(),
                       {"trials", "in distribution", "paper (Table 1)", "OOD (independent)",
                        "paper (Table 1, OOD at 100 demos)", "OOD (paired)"});
  if (audited) table.columns.push_back("audited symmetry");
  for (const Row& row : rows) {
    const std::optional<PaperRow> paper = paper_row(row.method, row.head);
    std::string paper_id = "-", paper_ood = "-";
    if (paper) {
      const auto at = std::find(kPaperDemoCounts.begin(), kPaperDemoCounts.end(), row.demos);
      if (at != kPaperDemoCounts.end())
        paper_id = format_fixed(
            paper->success[static_cast<std::size_t>(at - kPaperDemoCounts.begin())], 2);
      if (row.demos == 100) paper_ood = format_fixed(paper->ood_at_100, 2);
      paper_id += " (" + paper->label + ")";
    }
    std::vector<TableCell> cells = {text_cell(row.method + " / " + row.head),
                                    text_cell(std::to_string(row.demos))};
    if (seeds) cells.push_back(text_cell(std::to_string(row.train_seed)));
    cells.insert(
        cells.end(),
        {text_cell(std::to_string(row.trials)), text_cell(rate_text(row.id_success, row.id_ci)),
         text_cell(paper_id), text_cell(rate_text(row.ood_success, row.ood_ci)),
         text_cell(paper_ood), text_cell(rate_text(row.ood_paired_success, {}))});
    if (audited) cells.push_back(text_cell(symmetry_text(row.symmetry)));
    table.rows.push_back(std::move(cells));
  }
  return table;
}

Table table2_table(const std::vector<Table2Row>& rows, const std::string& id) {
  Table table;
  table.id = id;
  table.kind = "results";
  table.caption = "Table 2's analogue: success, counts and [Wilson 95%]";
  table.columns = {"method", "demos", "steps", "train", "ood (slot on its side)", "random-se3"};
  for (const Table2Row& row : rows) {
    table.rows.push_back({text_cell("flow / " + row.method), text_cell(std::to_string(row.demos)),
                          text_cell(std::to_string(row.steps)),
                          text_cell(counts_text(row.train.success, row.train.trials)),
                          text_cell(counts_text(row.ood.success, row.ood.trials)),
                          text_cell(counts_text(row.random_se3.success, row.random_se3.trials))});
  }
  table.rows.push_back(
      {text_cell("hand-centric (paper, real robot)"), text_cell("-"), text_cell("-"),
       text_cell(counts_text(kPaperTable2InDistribution[0], kPaperTable2InDistribution[1])),
       text_cell(counts_text(kPaperTable2OutOfDistribution[0], kPaperTable2OutOfDistribution[1]) +
                 " (horizontal stacks)"),
       text_cell("-")});
  return table;
}

}  // namespace handcentric::experiments
