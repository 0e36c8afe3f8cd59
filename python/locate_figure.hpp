#pragma once
// handcentric.locate_figure's drawing: the per-module error of handcentric.locate on a log axis,
// the first break marked, drawn with the project's chart library (experiments/chart.hpp). It is
// an extension of its own, handcentric._figure (figure_module.cpp), loaded only when a figure is
// drawn: the chart library's Cairo and the drawing library's other dependencies (OpenCV, Box2D,
// FCL) would take `import handcentric` from 11 shared libraries to 43.
#include <optional>
#include <string>
#include <vector>

namespace handcentric::python {

/// Writes `stem`.png and `stem`.svg: log10 of each row's error (labels[i], errors[i]; 0 drawn on
/// the bottom line 1e-16, above 1e4, infinite and NaN on the top one), the floor `relative`
/// dashed, and the row `first` (an index into labels, or none) with a marker of its own.
/// Throws InvalidArgument for no rows, labels and errors of different lengths or a `first` out
/// of range, and FileError naming the path when it cannot write.
void locate_figure(const std::vector<std::string>& labels, const std::vector<double>& errors,
                   std::optional<std::size_t> first, double relative, const std::string& title,
                   const std::string& stem);

}  // namespace handcentric::python
