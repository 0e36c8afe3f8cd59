#pragma once
// Charts for the report page and the tables' figures: grouped bars (success at one setting) and
// curves (success against a number, e.g. demos), each drawn once with Cairo and written as a PNG
// and an SVG (vector, with the DejaVu Sans font), so a page shows the SVG and a reader who wants
// pixels has the PNG beside it. Colours are Okabe-Ito's colour-blind-safe palette; every mark
// lies inside its axes (the y range is padded, the x range too), which chart_layout reports and
// mark_outside_axes checks, and no reference line runs through a bar's written value
// (label_under_line checks).
//
//   LineChart chart;
//   chart.x_label = "number of demos";
//   chart.curves.push_back({"hand_centric/flow", {10, 100}, {{0.98}, {1.0}}});
//   write_chart(chart, "out/success");   // out/success.png and out/success.svg
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "handcentric/experiments/wilson.hpp"
#include "handcentric/sim/draw.hpp"

namespace handcentric::experiments {

/// A value with its interval (drawn as an error bar), e.g. a success rate and its Wilson 95%.
struct ChartValue {
  double value = 0.0;
  std::optional<Interval> interval = std::nullopt;
};

/// Okabe-Ito colour `index` (wrapping), as 0-255 RGB: blue, vermillion, green, purple, orange,
/// sky blue, black, yellow (all eight, so that Table 1 with both C8 flow rows has no repeat).
std::array<unsigned char, 3> chart_colour(int index);

enum class Marker { dot, square, triangle };

/// One curve: a value (or none, a gap in the line) at each x, in increasing x.
struct Curve {
  std::string label = {};
  std::vector<double> x = {};
  std::vector<std::optional<ChartValue>> y = {};
  int colour = 0;  ///< chart_colour index
  Marker marker = Marker::dot;
  bool dashed = false;    ///< a dashed line and hollow markers
  bool in_legend = true;  ///< false: a companion curve that the notes explain (e.g. OOD, dashed)
};

struct LineChart {
  std::string title = {};
  std::string x_label = {};
  std::string y_label = "success";
  std::vector<Curve> curves = {};
  double y_min = 0.0, y_max = 1.0;
  /// The distinct x values evenly spaced, each a tick (a categorical axis: demo counts 5, 10, 20,
  /// ..., 100 read apart at the small end); false: a linear axis.
  bool evenly_spaced_x = false;
  /// The x axis of a linear axis; empty: the data's extent padded by 6% on each side. A range that
  /// puts a mark on or outside the frame is the mistake mark_outside_axes exists to catch.
  std::optional<std::array<double, 2>> x_range = std::nullopt;
  /// Lines of the legend after the curves' own (e.g. what the markers mean).
  std::vector<std::string> notes = {};
};

/// Grouped bars: one group per category (e.g. a method), one bar per series in it (e.g. train
/// and OOD scenes), the series' colour the same in every group, the value written above each
/// bar (so a 0.00 bar is read, not missed).
struct BarChart {
  std::string title = {};
  std::string y_label = "success";
  std::vector<std::string> groups = {};  ///< a '\n' splits a label over two lines
  std::vector<std::string> series = {};
  std::vector<std::vector<std::optional<ChartValue>>> values = {};  ///< [group][series]
  /// Optional reference values drawn as a black bar-wide tick, e.g. the paper's numbers: empty,
  /// or [group][series] like values.
  std::vector<std::vector<std::optional<double>>> reference = {};
  std::string reference_label = {};  ///< its legend line
  double y_max = 1.0;
  std::vector<std::string> notes = {};
};

/// Where a chart's marks land, in pixels of a width x height drawing: the axes' frame and the
/// box of every marker, error bar and bar.
struct ChartLayout {
  struct Box {
    double x0, y0, x1, y1;
    std::string what;  ///< "hand_centric/flow at 100", for messages
  };
  Box frame;
  std::vector<Box> marks;
  std::vector<Box> labels;  ///< the values written above bars
  std::vector<Box> lines;   ///< the reference lines (the paper's numbers), 2.5 px thick
};

ChartLayout chart_layout(const LineChart& chart, int width, int height);
ChartLayout chart_layout(const BarChart& chart, int width, int height);

/// The first mark not strictly inside the frame, as "<what> at (x0, y0)-(x1, y1) outside the
/// axes ..."; empty when every mark is inside.
std::string mark_outside_axes(const ChartLayout& layout);

/// The first value label that a reference line crosses (the line would hide the number), as
/// "<what> (value) at (x0, y0)-(x1, y1) is crossed by <what> (reference)"; empty when none is.
std::string label_under_line(const ChartLayout& layout);

/// The chart as an RGB image (tests read its pixels). Throws InvalidArgument for a chart with
/// nothing to draw, a curve whose x and y differ in length, a bar row of the wrong width, a
/// size outside [200, 4000], or a y range that is empty.
sim::Image render_chart(const LineChart& chart, int width = 900, int height = 520);
sim::Image render_chart(const BarChart& chart, int width = 900, int height = 520);

/// Writes `stem`.png (at twice the pixels, for sharp text) and `stem`.svg from one drawing,
/// each atomically. Throws as render_chart, and FileError naming the path when it cannot write.
void write_chart(const LineChart& chart, const std::string& stem, int width = 900,
                 int height = 520);
void write_chart(const BarChart& chart, const std::string& stem, int width = 900, int height = 520);

}  // namespace handcentric::experiments
