#include "locate_figure.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/experiments/chart.hpp"

namespace handcentric::python {
namespace {

// The log axis: decades from 1e-16 (the rounding of a float64 activation) to 1e4.
constexpr double kBottomDecade = -16.0, kTopDecade = 4.0;

double decade_of(double error) {
  if (std::isnan(error)) return kTopDecade;
  if (!(error > 0.0)) return kBottomDecade;
  return std::clamp(std::log10(error), kBottomDecade, kTopDecade);
}

}  // namespace

void locate_figure(const std::vector<std::string>& labels, const std::vector<double>& errors,
                   std::optional<std::size_t> first, double relative, const std::string& title,
                   const std::string& stem) {
  if (labels.empty() || labels.size() != errors.size()) {
    throw InvalidArgument("locate_figure needs one error per row, got " +
                          std::to_string(labels.size()) + " rows and " +
                          std::to_string(errors.size()) + " errors");
  }
  if (first && *first >= labels.size()) {
    throw InvalidArgument("locate_figure: the first break, row " + std::to_string(*first) +
                          ", is not one of the " + std::to_string(labels.size()) + " rows");
  }
  experiments::LineChart chart;
  chart.title = title;
  chart.x_label = "module or stage, in execution order (the legend names them)";
  chart.y_label = "log10 (error / (1 + c))";
  chart.y_min = kBottomDecade;
  chart.y_max = kTopDecade;
  chart.evenly_spaced_x = true;
  experiments::Curve rows{"error", {}, {}, 0, experiments::Marker::dot};
  experiments::Curve floor{
      "floor REL = " + format_significant(relative, 3), {}, {}, 6, experiments::Marker::dot, true};
  for (std::size_t i = 0; i < labels.size(); ++i) {
    const double x = static_cast<double>(i + 1);
    rows.x.push_back(x);
    rows.y.push_back(experiments::ChartValue{decade_of(errors[i])});
    floor.x.push_back(x);
    floor.y.push_back(experiments::ChartValue{decade_of(relative)});
    chart.notes.push_back(std::to_string(i + 1) + ": " + labels[i]);
  }
  chart.curves.push_back(std::move(rows));
  chart.curves.push_back(std::move(floor));
  if (first) {
    chart.curves.push_back({"first break: " + labels[*first],
                            {static_cast<double>(*first + 1)},
                            {experiments::ChartValue{decade_of(errors[*first])}},
                            1,
                            experiments::Marker::triangle});
  }
  experiments::write_chart(chart, stem);
}

}  // namespace handcentric::python
