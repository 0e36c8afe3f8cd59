#pragma once
// Table 1 (and Fig. 5's grid, the same rows with other heads) and Table 2 on the report page:
// our success rates with their Wilson 95% intervals beside the paper's numbers, as tables of
// the page's document (document.hpp).
#include <string>
#include <vector>

#include "handcentric/experiments/document.hpp"
#include "handcentric/experiments/results.hpp"
#include "handcentric/experiments/table2.hpp"

namespace handcentric::experiments {

/// The paper's Table 2 (a real robot, blade insertion): hand-centric 26/30 in distribution and
/// 5/5 out of distribution (horizontal stacks); no other method has a row there.
inline constexpr int kPaperTable2InDistribution[2] = {26, 30};
inline constexpr int kPaperTable2OutOfDistribution[2] = {5, 5};

/// "0.93 [0.79, 0.98]" for a rate and its interval; "-" when there is no rate.
std::string rate_text(const std::optional<double>& rate, const std::optional<Interval>& interval);

/// Table 1's one rendering (the report page, and table1.md through table1_markdown): one row per
/// row of `rows` (a method, head, demo count and training seed), in their order: in
/// distribution, OOD (independent) and OOD (paired) with Wilson intervals, the paper's numbers
/// beside them (its in-distribution rate at the paper's demo counts, its OOD rate at 100 demos);
/// a training seed column when the rows have several, and an audited symmetry column (per
/// group: yes or no, and the model's largest error) when a row was audited.
Table table1_table(const std::vector<Row>& rows, const std::string& id, const std::string& caption);

/// One row per method: train, ood and random-se3 success with counts and Wilson intervals, and
/// the paper's hand-centric row (with the Wilson intervals of its counts).
Table table2_table(const std::vector<Table2Row>& rows, const std::string& id);

}  // namespace handcentric::experiments
