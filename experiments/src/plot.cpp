#include "handcentric/experiments/plot.hpp"

#include <algorithm>

#include "handcentric/core/errors.hpp"
#include "handcentric/experiments/methods.hpp"

namespace handcentric::experiments {
namespace {

ChartValue value_of(double value, const std::optional<Interval>& interval) {
  return {value, interval};
}

}  // namespace

std::variant<BarChart, LineChart> table1_chart(const std::vector<Row>& rows) {
  if (rows.empty())
    throw InvalidArgument("draw_table1: no rows to draw (no cell has a result yet)");
  const std::uint64_t seed = rows.front().train_seed;
  std::vector<std::pair<std::string, std::string>> series;  // (method, head), in row order
  std::vector<int> counts;
  for (const Row& r : rows) {
    if (r.train_seed != seed) continue;
    if (std::find(series.begin(), series.end(), std::make_pair(r.method, r.head)) == series.end())
      series.emplace_back(r.method, r.head);
    if (std::find(counts.begin(), counts.end(), r.demos) == counts.end()) counts.push_back(r.demos);
  }
  std::sort(counts.begin(), counts.end());
  const auto find = [&](const std::pair<std::string, std::string>& s, int n) -> const Row* {
    for (const Row& r : rows) {
      if (r.method == s.first && r.head == s.second && r.demos == n && r.train_seed == seed)
        return &r;
    }
    return nullptr;
  };
  const std::string seed_note = "training seed " + std::to_string(seed);
  if (counts.size() == 1) {
    const int n = counts.front();
    BarChart chart;
    chart.title = "Closed-loop success at " + std::to_string(n) + " demos";
    chart.series = {"train-distribution scenes", "OOD scenes (own seed)"};
    chart.reference_label = "the paper (Table 1)";
    bool any_reference = false;
    for (const auto& s : series) {
      chart.groups.push_back(s.first + "\n" + s.second);
      const Row* r = find(s, n);
      std::vector<std::optional<ChartValue>> values(2);
      if (r && r->id_success) values[0] = value_of(*r->id_success, r->id_ci);
      if (r && r->ood_success) values[1] = value_of(*r->ood_success, r->ood_ci);
      chart.values.push_back(values);
      std::vector<std::optional<double>> reference(2);
      const auto paper = paper_row(s.first, s.second);
      const auto at = std::find(kPaperDemoCounts.begin(), kPaperDemoCounts.end(), n);
      if (paper && at != kPaperDemoCounts.end())
        reference[0] = paper->success[static_cast<std::size_t>(at - kPaperDemoCounts.begin())];
      if (paper && n == 100) reference[1] = paper->ood_at_100;
      any_reference = any_reference || reference[0] || reference[1];
      chart.reference.push_back(reference);
    }
    if (!any_reference) chart.reference.clear();
    chart.notes = {"bars: Wilson 95% intervals", seed_note};
    return chart;
  }
  LineChart chart;
  chart.title = "Closed-loop success against the number of demos";
  chart.x_label = "number of demos";
  chart.evenly_spaced_x = true;
  for (std::size_t k = 0; k < series.size(); ++k) {
    Curve id{series[k].first + "/" + series[k].second, {}, {}, static_cast<int>(k)};
    Curve ood{"", {}, {}, static_cast<int>(k), Marker::square, true, false};
    for (const int n : counts) {
      const Row* r = find(series[k], n);
      id.x.push_back(n);
      ood.x.push_back(n);
      id.y.push_back(r && r->id_success
                         ? std::optional<ChartValue>(value_of(*r->id_success, r->id_ci))
                         : std::nullopt);
      ood.y.push_back(r && r->ood_success
                          ? std::optional<ChartValue>(value_of(*r->ood_success, r->ood_ci))
                          : std::nullopt);
    }
    ood.label = id.label + ", OOD";
    chart.curves.push_back(std::move(id));
    chart.curves.push_back(std::move(ood));
  }
  chart.notes = {"solid, dots: train scenes", "dashed, squares: OOD scenes",
                 "bars: Wilson 95% intervals", seed_note};
  return chart;
}

sim::Image draw_table1(const std::vector<Row>& rows, int width, int height) {
  return std::visit([&](const auto& chart) { return render_chart(chart, width, height); },
                    table1_chart(rows));
}

void write_table1_figure(const std::string& stem, const std::vector<Row>& rows) {
  std::visit([&](const auto& chart) { write_chart(chart, stem); }, table1_chart(rows));
}

}  // namespace handcentric::experiments
