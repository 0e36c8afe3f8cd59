#pragma once
// Table 1 as a figure (chart.hpp): with one demo count, grouped bars per method and head (train
// scenes, independent OOD scenes), the paper's number as a black tick where it has one; with
// several, success against demos, one colour per method and head, filled dots on a solid line for
// the train scenes and hollow squares on a dashed line for the OOD scenes. Wilson 95% intervals
// as bars; the first training seed's rows.
#include <string>
#include <variant>
#include <vector>

#include "handcentric/experiments/chart.hpp"
#include "handcentric/experiments/results.hpp"
#include "handcentric/sim/draw.hpp"

namespace handcentric::experiments {

/// The chart of `rows`: a BarChart when they have one demo count, a LineChart otherwise. Throws
/// InvalidArgument for no rows.
std::variant<BarChart, LineChart> table1_chart(const std::vector<Row>& rows);

/// table1_chart as an RGB image (width x height pixels).
sim::Image draw_table1(const std::vector<Row>& rows, int width = 900, int height = 520);

/// table1_chart written as `stem`.png and `stem`.svg, each atomically.
void write_table1_figure(const std::string& stem, const std::vector<Row>& rows);

}  // namespace handcentric::experiments
