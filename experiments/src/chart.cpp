#include "handcentric/experiments/chart.hpp"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>

#include "handcentric/core/atomic_file.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/sim/canvas.hpp"

namespace handcentric::experiments {
namespace {

using Box = ChartLayout::Box;
using sim::Align;
using sim::lines_of;
using sim::set_grey;
using sim::text;
using sim::text_width;
using sim::white_page;

constexpr double kMarker = 4.5;      // marker half size, px
constexpr double kCurveShift = 1.5;  // px between curves at one x, so their bars stay apart
constexpr double kLegendText = 12.0, kNoteText = 11.0;  // px

struct Frame {
  double x0, y0, x1, y1;
};

// The axes' frame, leaving room on the right for the widest legend line (a 40 px key before a
// label; notes start at the key).
Frame frame_of(int width, int height, const std::vector<std::string>& labels,
               const std::vector<std::string>& notes) {
  double legend = 0.0;
  for (const std::string& label : labels)
    legend = std::max(legend, 40.0 + text_width(label, kLegendText));
  for (const std::string& note : notes) legend = std::max(legend, text_width(note, kNoteText));
  const double x1 = std::max(0.5 * width, width - legend - 36.0);
  return {68.0, 46.0, x1, height - 62.0};
}

std::vector<std::string> legend_labels(const LineChart& chart) {
  std::vector<std::string> labels;
  for (const Curve& c : chart.curves)
    if (c.in_legend) labels.push_back(c.label);
  return labels;
}

std::vector<std::string> legend_labels(const BarChart& chart) {
  std::vector<std::string> labels = chart.series;
  if (!chart.reference.empty()) labels.push_back(chart.reference_label);
  return labels;
}

void check_size(int width, int height) {
  if (width < 200 || width > 4000 || height < 200 || height > 4000) {
    throw InvalidArgument("chart size " + std::to_string(width) + " x " + std::to_string(height) +
                          " is outside [200, 4000]: choose another width or height");
  }
}

void check_value(const std::string& title, const std::optional<ChartValue>& v) {
  if (!v) return;
  const bool finite =
      std::isfinite(v->value) &&
      (!v->interval || (std::isfinite(v->interval->lo) && std::isfinite(v->interval->hi)));
  if (!finite)
    throw InvalidArgument("chart '" + title + "': a value or interval is not finite: drop it");
}

void validate(const LineChart& chart) {
  if (!(chart.y_max > chart.y_min) || !std::isfinite(chart.y_min) || !std::isfinite(chart.y_max))
    throw InvalidArgument("chart '" + chart.title + "': y range is empty: give y_min < y_max");
  bool any = false;
  for (const Curve& c : chart.curves) {
    if (c.x.size() != c.y.size()) {
      throw InvalidArgument("chart '" + chart.title + "': curve '" + c.label + "' has " +
                            std::to_string(c.x.size()) + " x and " + std::to_string(c.y.size()) +
                            " y values: give one y per x");
    }
    for (std::size_t i = 0; i < c.x.size(); ++i) {
      if (!std::isfinite(c.x[i]))
        throw InvalidArgument("chart '" + chart.title + "': curve '" + c.label + "' has x NaN");
      check_value(chart.title, c.y[i]);
      any = any || c.y[i].has_value();
    }
  }
  if (!any) throw InvalidArgument("chart '" + chart.title + "': nothing to draw (no value)");
  if (chart.x_range && !((*chart.x_range)[1] > (*chart.x_range)[0]))
    throw InvalidArgument("chart '" + chart.title + "': x range is empty: give lo < hi");
}

void validate(const BarChart& chart) {
  if (!(chart.y_max > 0.0) || !std::isfinite(chart.y_max))
    throw InvalidArgument("chart '" + chart.title + "': y_max must be > 0");
  if (chart.groups.empty() || chart.series.empty())
    throw InvalidArgument("chart '" + chart.title + "': nothing to draw (no group or series)");
  const auto check_shape = [&](std::size_t rows, const std::function<std::size_t(std::size_t)>& at,
                               const std::string& what) {
    if (rows != chart.groups.size()) {
      throw InvalidArgument("chart '" + chart.title + "': " + what + " has " +
                            std::to_string(rows) + " rows for " +
                            std::to_string(chart.groups.size()) + " groups: give one per group");
    }
    for (std::size_t g = 0; g < rows; ++g) {
      if (at(g) != chart.series.size()) {
        throw InvalidArgument("chart '" + chart.title + "': " + what + " of group '" +
                              chart.groups[g] + "' has " + std::to_string(at(g)) + " values for " +
                              std::to_string(chart.series.size()) + " series");
      }
    }
  };
  check_shape(
      chart.values.size(), [&](std::size_t g) { return chart.values[g].size(); }, "values");
  if (!chart.reference.empty()) {
    check_shape(
        chart.reference.size(), [&](std::size_t g) { return chart.reference[g].size(); },
        "reference");
  }
  for (const auto& row : chart.values)
    for (const auto& v : row) check_value(chart.title, v);
}

// --- Line charts: where things go -----------------------------------------------------------

struct LineGeometry {
  Frame frame;
  double x_lo, x_hi;  // data range mapped onto [frame.x0 + pad, frame.x1 - pad]
  double pad;         // px inside the frame on each side (0 with an explicit x_range)
  double y_lo, y_hi;  // padded y range mapped onto the frame
  std::vector<double> ticks;
  bool even = false;  // the ticks evenly spaced, x placed by its rank among them
  double px(double x, double shift) const {
    double at = (x - x_lo) / (x_hi - x_lo);
    if (even && ticks.size() > 1) {
      const auto it = std::lower_bound(ticks.begin(), ticks.end(), x);
      at = static_cast<double>(it - ticks.begin()) / static_cast<double>(ticks.size() - 1);
    }
    return frame.x0 + pad + at * (frame.x1 - frame.x0 - 2.0 * pad) + shift;
  }
  double py(double y) const {
    return frame.y1 - (y - y_lo) / (y_hi - y_lo) * (frame.y1 - frame.y0);
  }
  double shift(std::size_t curve, std::size_t curves) const {
    return (static_cast<double>(curve) - 0.5 * (static_cast<double>(curves) - 1.0)) * kCurveShift;
  }
};

LineGeometry line_geometry(const LineChart& chart, int width, int height) {
  LineGeometry g{};
  g.frame = frame_of(width, height, legend_labels(chart), chart.notes);
  std::vector<double> xs;
  for (const Curve& c : chart.curves)
    for (std::size_t i = 0; i < c.x.size(); ++i)
      if (c.y[i]) xs.push_back(c.x[i]);
  std::sort(xs.begin(), xs.end());
  xs.erase(std::unique(xs.begin(), xs.end()), xs.end());
  g.ticks = xs;
  const double y_pad = 0.04 * (chart.y_max - chart.y_min);
  g.y_lo = chart.y_min - y_pad;
  g.y_hi = chart.y_max + y_pad;
  if (chart.x_range && !chart.evenly_spaced_x) {
    g.x_lo = (*chart.x_range)[0];
    g.x_hi = (*chart.x_range)[1];
    g.pad = 0.0;
    return g;
  }
  g.even = chart.evenly_spaced_x;
  g.x_lo = xs.front();
  g.x_hi = xs.back();
  if (g.x_hi == g.x_lo) {  // one x: centre it
    g.x_lo -= 1.0;
    g.x_hi += 1.0;
  }
  // Room for the widest spread of curves at one x and a marker, and 6% of the axis.
  const double spread = 0.5 * (static_cast<double>(chart.curves.size()) - 1.0) * kCurveShift;
  g.pad = std::max(0.06 * (g.frame.x1 - g.frame.x0), spread + kMarker + 6.0);
  return g;
}

// --- Bar charts: where things go ------------------------------------------------------------

struct BarGeometry {
  Frame frame;
  double group_width, bar_width, y_hi;
  double bar_x0(std::size_t group, std::size_t series, std::size_t n_series) const {
    const double centre = frame.x0 + (static_cast<double>(group) + 0.5) * group_width;
    return centre - 0.5 * static_cast<double>(n_series) * bar_width +
           static_cast<double>(series) * bar_width;
  }
  double py(double y) const { return frame.y1 - y / y_hi * (frame.y1 - frame.y0); }
};

// The value written above bar (group, series): its text and its box. It sits 4 px above the
// bar or its interval; a reference line through that box would hide the number, so then it
// sits above the line instead. One function for the drawing and for chart_layout.
struct ValueLabel {
  std::string text;
  Box box;
};
constexpr double kValueText = 9.0;  // px

ValueLabel value_label(const BarGeometry& g, const BarChart& chart, std::size_t group,
                       std::size_t series) {
  const ChartValue& v = *chart.values[group][series];
  double top = g.py(v.value);
  if (v.interval) top = std::min(top, g.py(v.interval->hi));
  const std::optional<double> reference =
      chart.reference.empty() ? std::nullopt : chart.reference[group][series];
  if (reference) {
    const double r = g.py(*reference);
    // The label's box spans top - 4 - 9 .. top - 4, the line r +- 1.25.
    if (r > top - 18.0 && r < top + 2.0) top = r - 2.0;
  }
  const std::string text = format_fixed(v.value, 2);
  const double centre = g.bar_x0(group, series, chart.series.size()) + 0.5 * g.bar_width;
  const double half = 0.5 * text_width(text, kValueText);
  return {text,
          {centre - half, top - 4.0 - kValueText, centre + half, top - 4.0,
           chart.groups[group] + " " + chart.series[series] + " (value)"}};
}

BarGeometry bar_geometry(const BarChart& chart, int width, int height) {
  BarGeometry g{};
  g.frame = frame_of(width, height, legend_labels(chart), chart.notes);
  g.group_width = (g.frame.x1 - g.frame.x0) / static_cast<double>(chart.groups.size());
  g.bar_width = std::min(34.0, 0.78 * g.group_width / static_cast<double>(chart.series.size()));
  g.y_hi = 1.16 * chart.y_max;  // room for the value above a full bar
  return g;
}

// --- Drawing --------------------------------------------------------------------------------

void set_colour(cairo_t* cr, int index) {
  const auto c = chart_colour(index);
  cairo_set_source_rgb(cr, c[0] / 255.0, c[1] / 255.0, c[2] / 255.0);
}

void marker(cairo_t* cr, Marker shape, double x, double y, int colour, bool hollow) {
  cairo_new_path(cr);
  switch (shape) {
    case Marker::dot:
      cairo_arc(cr, x, y, kMarker, 0.0, 2.0 * std::numbers::pi);
      break;
    case Marker::square:
      cairo_rectangle(cr, x - kMarker, y - kMarker, 2.0 * kMarker, 2.0 * kMarker);
      break;
    case Marker::triangle:
      cairo_move_to(cr, x, y - kMarker);
      cairo_line_to(cr, x + kMarker, y + kMarker);
      cairo_line_to(cr, x - kMarker, y + kMarker);
      cairo_close_path(cr);
      break;
  }
  if (hollow) {
    cairo_set_source_rgb(cr, 1.0, 1.0, 1.0);
    cairo_fill_preserve(cr);
    set_colour(cr, colour);
    cairo_set_line_width(cr, 1.6);
    cairo_stroke(cr);
  } else {
    set_colour(cr, colour);
    cairo_fill(cr);
  }
}

// The frame, horizontal grid lines and y ticks every 0.2 (of [lo, hi]), the y label and title.
void axes(cairo_t* cr, const Frame& f, const std::function<double(double)>& py, double lo,
          double hi, const std::string& title, const std::string& y_label) {
  cairo_set_line_width(cr, 1.0);
  for (double y = lo; y <= hi + 1e-9; y += 0.2 * (hi - lo)) {
    set_grey(cr, 0.88);
    cairo_move_to(cr, f.x0, std::round(py(y)) + 0.5);
    cairo_line_to(cr, f.x1, std::round(py(y)) + 0.5);
    cairo_stroke(cr);
    set_grey(cr, 0.15);
    text(cr, format_fixed(y, 1), f.x0 - 8.0, py(y) + 4.0, 11.0, Align::right);
  }
  set_grey(cr, 0.15);
  cairo_rectangle(cr, f.x0 + 0.5, f.y0 + 0.5, f.x1 - f.x0 - 1.0, f.y1 - f.y0 - 1.0);
  cairo_stroke(cr);
  text(cr, title, f.x0, f.y0 - 16.0, 15.0, Align::left, true);
  cairo_save(cr);
  cairo_translate(cr, 18.0, 0.5 * (f.y0 + f.y1));
  cairo_rotate(cr, -std::numbers::pi / 2.0);
  text(cr, y_label, 0.0, 0.0, 13.0, Align::centre);
  cairo_restore(cr);
}

void error_bar(cairo_t* cr, double x, double y_lo, double y_hi, int colour) {
  set_colour(cr, colour);
  cairo_set_line_width(cr, 1.2);
  cairo_move_to(cr, x, y_lo);
  cairo_line_to(cr, x, y_hi);
  cairo_move_to(cr, x - 3.0, y_lo);
  cairo_line_to(cr, x + 3.0, y_lo);
  cairo_move_to(cr, x - 3.0, y_hi);
  cairo_line_to(cr, x + 3.0, y_hi);
  cairo_stroke(cr);
}

void notes(cairo_t* cr, const std::vector<std::string>& lines, double x, double y) {
  set_grey(cr, 0.35);
  for (const std::string& line : lines) {
    text(cr, line, x, y, kNoteText);
    y += 17.0;
  }
}

std::string tick_text(double x) {
  return format_significant(x, 6);
}

void draw(cairo_t* cr, const LineChart& chart, int width, int height) {
  const LineGeometry g = line_geometry(chart, width, height);
  white_page(cr, width, height);
  axes(
      cr, g.frame, [&](double y) { return g.py(y); }, chart.y_min, chart.y_max, chart.title,
      chart.y_label);
  set_grey(cr, 0.15);
  cairo_set_line_width(cr, 1.0);
  for (const double x : g.ticks) {
    const double at = std::round(g.px(x, 0.0)) + 0.5;
    cairo_move_to(cr, at, g.frame.y1);
    cairo_line_to(cr, at, g.frame.y1 + 5.0);
    cairo_stroke(cr);
    text(cr, tick_text(x), at, g.frame.y1 + 19.0, 11.0, Align::centre);
  }
  text(cr, chart.x_label, 0.5 * (g.frame.x0 + g.frame.x1), height - 16.0, 13.0, Align::centre);
  // Inside the frame only, whatever a caller's x_range says.
  cairo_save(cr);
  cairo_rectangle(cr, g.frame.x0, g.frame.y0, g.frame.x1 - g.frame.x0, g.frame.y1 - g.frame.y0);
  cairo_clip(cr);
  for (std::size_t s = 0; s < chart.curves.size(); ++s) {
    const Curve& c = chart.curves[s];
    const double shift = g.shift(s, chart.curves.size());
    set_colour(cr, c.colour);
    cairo_set_line_width(cr, 2.0);
    const double dash[] = {6.0, 4.0};
    cairo_set_dash(cr, dash, c.dashed ? 2 : 0, 0.0);
    bool drawing = false;
    for (std::size_t i = 0; i < c.x.size(); ++i) {
      if (!c.y[i]) {
        drawing = false;
        continue;
      }
      const double x = g.px(c.x[i], shift), y = g.py(c.y[i]->value);
      if (drawing) {
        cairo_line_to(cr, x, y);
      } else {
        cairo_move_to(cr, x, y);
      }
      drawing = true;
    }
    cairo_stroke(cr);
    cairo_set_dash(cr, dash, 0, 0.0);
    for (std::size_t i = 0; i < c.x.size(); ++i) {
      if (!c.y[i]) continue;
      const double x = g.px(c.x[i], shift);
      if (c.y[i]->interval)
        error_bar(cr, x, g.py(c.y[i]->interval->lo), g.py(c.y[i]->interval->hi), c.colour);
      marker(cr, c.marker, x, g.py(c.y[i]->value), c.colour, c.dashed);
    }
  }
  cairo_restore(cr);
  // Legend.
  double y = g.frame.y0 + 10.0;
  const double x = g.frame.x1 + 18.0;
  for (const Curve& c : chart.curves) {
    if (!c.in_legend) continue;
    set_colour(cr, c.colour);
    cairo_set_line_width(cr, 2.0);
    const double dash[] = {6.0, 4.0};
    cairo_set_dash(cr, dash, c.dashed ? 2 : 0, 0.0);
    cairo_move_to(cr, x, y);
    cairo_line_to(cr, x + 30.0, y);
    cairo_stroke(cr);
    cairo_set_dash(cr, dash, 0, 0.0);
    marker(cr, c.marker, x + 15.0, y, c.colour, c.dashed);
    set_grey(cr, 0.1);
    text(cr, c.label, x + 40.0, y + 4.0, kLegendText);
    y += 20.0;
  }
  notes(cr, chart.notes, x, y + 12.0);
}

void draw(cairo_t* cr, const BarChart& chart, int width, int height) {
  const BarGeometry g = bar_geometry(chart, width, height);
  white_page(cr, width, height);
  axes(
      cr, g.frame, [&](double y) { return g.py(y); }, 0.0, chart.y_max, chart.title, chart.y_label);
  const std::size_t n = chart.series.size();
  for (std::size_t gi = 0; gi < chart.groups.size(); ++gi) {
    for (std::size_t s = 0; s < n; ++s) {
      const double x0 = g.bar_x0(gi, s, n), x1 = x0 + g.bar_width;
      const std::optional<ChartValue>& v = chart.values[gi][s];
      if (!v) continue;
      set_colour(cr, static_cast<int>(s));
      cairo_rectangle(cr, x0 + 1.0, g.py(v->value), g.bar_width - 2.0, g.frame.y1 - g.py(v->value));
      cairo_fill(cr);
      if (v->interval) {  // black (the palette's last colour), whatever the bar's colour
        error_bar(cr, 0.5 * (x0 + x1), g.py(v->interval->lo), g.py(v->interval->hi), 6);
      }
      if (!chart.reference.empty() && chart.reference[gi][s]) {
        const double r = g.py(*chart.reference[gi][s]);
        cairo_set_source_rgb(cr, 0.0, 0.0, 0.0);
        cairo_set_line_width(cr, 2.5);
        cairo_move_to(cr, x0 - 1.0, r);
        cairo_line_to(cr, x1 + 1.0, r);
        cairo_stroke(cr);
      }
      set_grey(cr, 0.1);
      const ValueLabel label = value_label(g, chart, gi, s);
      text(cr, label.text, 0.5 * (x0 + x1), label.box.y1, kValueText, Align::centre);
    }
    set_grey(cr, 0.1);
    const std::vector<std::string> lines = lines_of(chart.groups[gi]);
    const double centre = g.frame.x0 + (static_cast<double>(gi) + 0.5) * g.group_width;
    for (std::size_t l = 0; l < lines.size(); ++l)
      text(cr, lines[l], centre, g.frame.y1 + 17.0 + 14.0 * static_cast<double>(l), 11.0,
           Align::centre);
  }
  double y = g.frame.y0 + 10.0;
  const double x = g.frame.x1 + 18.0;
  for (std::size_t s = 0; s < n; ++s) {
    set_colour(cr, static_cast<int>(s));
    cairo_rectangle(cr, x + 4.0, y - 7.0, 22.0, 12.0);
    cairo_fill(cr);
    set_grey(cr, 0.1);
    text(cr, chart.series[s], x + 40.0, y + 4.0, kLegendText);
    y += 20.0;
  }
  if (!chart.reference.empty()) {
    cairo_set_source_rgb(cr, 0.0, 0.0, 0.0);
    cairo_set_line_width(cr, 2.5);
    cairo_move_to(cr, x + 4.0, y);
    cairo_line_to(cr, x + 26.0, y);
    cairo_stroke(cr);
    text(cr, chart.reference_label, x + 40.0, y + 4.0, kLegendText);
    y += 20.0;
  }
  notes(cr, chart.notes, x, y + 12.0);
}

// --- Surfaces -------------------------------------------------------------------------------

template <class Chart>
sim::Image render(const Chart& chart, int width, int height) {
  check_size(width, height);
  validate(chart);
  const sim::Canvas canvas(width, height);
  draw(canvas.cr(), chart, width, height);
  return canvas.image();
}

template <class Chart>
void write(const Chart& chart, const std::string& stem, int width, int height) {
  check_size(width, height);
  validate(chart);
  const sim::Canvas canvas(2 * width, 2 * height);  // twice the pixels, for sharp text
  cairo_scale(canvas.cr(), 2.0, 2.0);
  draw(canvas.cr(), chart, width, height);
  const std::string png = canvas.png();
  const std::string svg =
      sim::svg_drawing(width, height, [&](cairo_t* cr) { draw(cr, chart, width, height); });
  write_file_atomically(stem + ".png", png);
  write_file_atomically(stem + ".svg", svg);
}

// "(x0, y0)-(x1, y1)", one decimal.
std::string box_text(const Box& b) {
  std::string text = "(";  // appends: GCC 12 warns, falsely, on "(" + std::string&&
  text += format_fixed(b.x0, 1);
  text += ", ";
  text += format_fixed(b.y0, 1);
  text += ")-(";
  text += format_fixed(b.x1, 1);
  text += ", ";
  text += format_fixed(b.y1, 1);
  return text + ")";
}

template <class Geometry>
Box frame_box(const Geometry& g) {
  return {g.frame.x0, g.frame.y0, g.frame.x1, g.frame.y1, "the axes"};
}

}  // namespace

std::array<unsigned char, 3> chart_colour(int index) {
  static constexpr std::array<unsigned char, 3> kOkabeIto[] = {
      {0, 114, 178}, {213, 94, 0},   {0, 158, 115}, {204, 121, 167},
      {230, 159, 0}, {86, 180, 233}, {0, 0, 0},     {240, 228, 66}};
  const int n = static_cast<int>(std::size(kOkabeIto));
  return kOkabeIto[((index % n) + n) % n];
}

ChartLayout chart_layout(const LineChart& chart, int width, int height) {
  check_size(width, height);
  validate(chart);
  const LineGeometry g = line_geometry(chart, width, height);
  ChartLayout layout;
  layout.frame = frame_box(g);
  for (std::size_t s = 0; s < chart.curves.size(); ++s) {
    const Curve& c = chart.curves[s];
    for (std::size_t i = 0; i < c.x.size(); ++i) {
      if (!c.y[i]) continue;
      const double x = g.px(c.x[i], g.shift(s, chart.curves.size())), y = g.py(c.y[i]->value);
      const std::string what = c.label + " at " + tick_text(c.x[i]);
      layout.marks.push_back({x - kMarker, y - kMarker, x + kMarker, y + kMarker, what});
      if (c.y[i]->interval) {
        layout.marks.push_back({x - 3.0, g.py(c.y[i]->interval->hi), x + 3.0,
                                g.py(c.y[i]->interval->lo), what + " (interval)"});
      }
    }
  }
  return layout;
}

ChartLayout chart_layout(const BarChart& chart, int width, int height) {
  check_size(width, height);
  validate(chart);
  const BarGeometry g = bar_geometry(chart, width, height);
  ChartLayout layout;
  layout.frame = frame_box(g);
  for (std::size_t gi = 0; gi < chart.groups.size(); ++gi) {
    for (std::size_t s = 0; s < chart.series.size(); ++s) {
      const std::optional<ChartValue>& v = chart.values[gi][s];
      if (!v) continue;
      const double x0 = g.bar_x0(gi, s, chart.series.size());
      const std::string what = chart.groups[gi] + " " + chart.series[s];
      layout.marks.push_back({x0, g.py(v->value), x0 + g.bar_width, g.frame.y1, what});
      if (v->interval) {
        layout.marks.push_back({x0, g.py(v->interval->hi), x0 + g.bar_width, g.py(v->interval->lo),
                                what + " (interval)"});
      }
      layout.labels.push_back(value_label(g, chart, gi, s).box);
      if (!chart.reference.empty() && chart.reference[gi][s]) {
        const double r = g.py(*chart.reference[gi][s]);
        layout.lines.push_back(
            {x0 - 1.0, r - 1.25, x0 + g.bar_width + 1.0, r + 1.25, what + " (reference)"});
      }
    }
  }
  return layout;
}

std::string label_under_line(const ChartLayout& layout) {
  for (const Box& label : layout.labels) {
    for (const Box& line : layout.lines) {
      if (label.x1 <= line.x0 || line.x1 <= label.x0 || label.y1 <= line.y0 || line.y1 <= label.y0)
        continue;
      return label.what + " at " + box_text(label) + " is crossed by " + line.what;
    }
  }
  return "";
}

std::string mark_outside_axes(const ChartLayout& layout) {
  const Box& f = layout.frame;
  for (const Box& m : layout.marks) {
    if (m.x0 >= f.x0 && m.x1 <= f.x1 && m.y0 >= f.y0 && m.y1 <= f.y1) continue;
    return m.what + " at " + box_text(m) + " outside the axes " + box_text(f);
  }
  return "";
}

sim::Image render_chart(const LineChart& chart, int width, int height) {
  return render(chart, width, height);
}

sim::Image render_chart(const BarChart& chart, int width, int height) {
  return render(chart, width, height);
}

void write_chart(const LineChart& chart, const std::string& stem, int width, int height) {
  write(chart, stem, width, height);
}

void write_chart(const BarChart& chart, const std::string& stem, int width, int height) {
  write(chart, stem, width, height);
}

}  // namespace handcentric::experiments
