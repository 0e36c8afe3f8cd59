#pragma once
// Table 1 as a figure: success against the number of demos, one colour per method and head,
// filled dots on a solid line for the training-distribution scenes, hollow squares on a dashed
// line for the independent OOD scenes, Wilson 95% intervals as bars (first training seed).
#include <string>
#include <vector>

#include "handcentric/experiments/results.hpp"
#include "handcentric/sim/draw.hpp"

namespace handcentric::experiments {

/// The figure as an RGB image (width x height pixels). Throws InvalidArgument for no rows.
sim::Image draw_table1(const std::vector<Row>& rows, int width = 960, int height = 600);

/// draw_table1, written atomically as a PNG.
void write_table1_png(const std::string& path, const std::vector<Row>& rows);

}  // namespace handcentric::experiments
