#include "handcentric/experiments/profile_plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "handcentric/core/errors.hpp"
#include "handcentric/sim/canvas.hpp"

namespace handcentric::experiments {
namespace {

using sim::Align;
using sim::set_rgb;
using sim::text;

// Paul Tol's "bright" scheme (colour-blind safe), one per profile in order.
constexpr std::array<std::array<int, 3>, 7> kProfileColours = {{{68, 119, 170},
                                                                {238, 102, 119},
                                                                {34, 136, 51},
                                                                {204, 187, 68},
                                                                {102, 204, 238},
                                                                {170, 51, 119},
                                                                {60, 60, 60}}};

constexpr double kLowestDecade = -16.0;
// Pixels between the axes' box and the outermost grid line, so that a mark on the first or last
// size, or on the bottom decade, stays inside the box.
constexpr int kInset = 12;
constexpr double kProfileTick = 11.5, kProfileLabel = 13.0, kProfileLegend = 11.0;  // px

// The legend's label of a profile, wrapped at spaces into at most two lines of kLabelChars (the
// legend's width at its font), the second shortened from the front if it is still too long. A
// policy's component goes without saying.
constexpr std::size_t kLabelChars = 31;

std::vector<std::string> label_of(const props::Profile& p) {
  std::string label = p.name;
  if (p.component != props::Component::policy) {
    label.push_back(' ');
    label.append(props::to_string(p.component));
  }
  std::vector<std::string> lines;
  std::string line;
  std::size_t at = 0;
  while (at < label.size()) {
    std::size_t end = label.find(' ', at);
    if (end == std::string::npos) end = label.size();
    const std::string word = label.substr(at, end - at);
    if (!line.empty() && line.size() + 1 + word.size() > kLabelChars && lines.empty()) {
      lines.push_back(line);
      line.clear();
    }
    if (!line.empty()) line.push_back(' ');
    line.append(word);
    at = end + 1;
  }
  lines.push_back(line);
  for (std::string& l : lines)
    if (l.size() > kLabelChars) l.replace(0, l.size() - (kLabelChars - 3), "...");
  return lines;
}

}  // namespace

sim::Image draw_profiles(const std::vector<props::Profile>& profiles, int width, int height) {
  if (profiles.empty()) throw InvalidArgument("draw_profiles: no profiles to draw");
  const props::Group group = profiles.front().group;
  for (const props::Profile& p : profiles) {
    if (p.group != group)
      throw InvalidArgument("draw_profiles: profiles of " + props::to_string(group) + " and " +
                            props::to_string(p.group) + " in one plot; draw one group at a time");
    if (p.points.empty())
      throw InvalidArgument("draw_profiles: profile '" + p.name + "' has no sizes");
  }
  const bool c8 = group == props::Group::c8;
  double x_lo = 1e300, x_hi = 0.0, y_hi = 1e-300;
  for (const props::Profile& p : profiles) {
    for (const props::ProfilePoint& point : p.points) {
      const double x = c8 ? point.size * 180.0 / std::numbers::pi : point.size;
      x_lo = std::min(x_lo, x);
      x_hi = std::max(x_hi, x);
      for (double y : {point.pointwise.max, point.distribution ? point.distribution->max : 0.0})
        if (std::isfinite(y)) y_hi = std::max(y_hi, y);
    }
  }
  // x: log decades around the sizes (c8: 0 to the next multiple of 45 deg); y: decades.
  const double ax_lo = c8 ? 0.0 : std::floor(std::log10(x_lo));
  const double ax_hi = c8 ? 45.0 * std::ceil(x_hi / 45.0) : std::ceil(std::log10(x_hi));
  // A decade of headroom when the largest value sits near the top, so its mark stays inside.
  const double ay_hi = std::max(0.0, std::ceil(std::log10(y_hi) + 0.15));
  const double ay_lo = kLowestDecade;
  const sim::Canvas canvas(width, height);
  cairo_t* cr = canvas.cr();
  const double left = 80, right = width - 290, top = 60, bottom = height - 60;
  const auto x_of = [&](double size) {
    const double x = c8 ? size * 180.0 / std::numbers::pi : std::log10(size);
    return std::round(left + kInset + (right - left - 2 * kInset) * (x - ax_lo) / (ax_hi - ax_lo));
  };
  const auto y_of = [&](double value) {
    const double y = value > 0.0 && std::isfinite(value)
                         ? std::clamp(std::log10(value), ay_lo, ay_hi)
                         : (std::isfinite(value) ? ay_lo : ay_hi);
    return std::round(bottom - kInset -
                      (bottom - top - 2 * kInset) * (y - ay_lo) / (ay_hi - ay_lo));
  };
  const auto line = [&](double x0, double y0, double x1, double y1) {
    cairo_move_to(cr, x0, y0);
    cairo_line_to(cr, x1, y1);
    cairo_stroke(cr);
  };
  const auto circle = [&](double x, double y, double r, bool filled) {
    cairo_new_sub_path(cr);
    cairo_arc(cr, x, y, r, 0.0, 2.0 * std::numbers::pi);
    if (filled) {
      cairo_fill(cr);
    } else {
      cairo_stroke(cr);
    }
  };
  // Grid and ticks.
  cairo_set_line_width(cr, 1.0);
  const int y_step = ay_hi - ay_lo > 10 ? 2 : 1;
  for (int d = static_cast<int>(ay_lo); d <= static_cast<int>(ay_hi); d += y_step) {
    const double y = y_of(std::pow(10.0, d)) + 0.5;
    set_rgb(cr, 225, 225, 225);
    line(left, y, right, y);
    set_rgb(cr, 20, 20, 20);
    text(cr, "1e" + std::to_string(d), left - 8, y + 4, kProfileTick, Align::right);
  }
  if (c8) {
    for (int deg = 0; deg <= static_cast<int>(ax_hi); deg += 45) {
      const double x = x_of(deg * std::numbers::pi / 180.0) + 0.5;
      set_rgb(cr, 200, 200, 235);
      line(x, top, x, bottom);
      set_rgb(cr, 20, 20, 20);
      text(cr, std::to_string(deg), x, bottom + 20, kProfileTick, Align::centre);
    }
  } else {
    for (int d = static_cast<int>(ax_lo); d <= static_cast<int>(ax_hi); ++d) {
      const double x = x_of(std::pow(10.0, d)) + 0.5;
      set_rgb(cr, 225, 225, 225);
      line(x, top, x, bottom);
      set_rgb(cr, 20, 20, 20);
      text(cr, "1e" + std::to_string(d), x, bottom + 20, kProfileTick, Align::centre);
    }
  }
  cairo_rectangle(cr, left + 0.5, top + 0.5, right - left, bottom - top);
  cairo_stroke(cr);
  const std::string unit =
      c8 ? "deg about z (C8's elements: the blue lines)" : props::profile_unit(group);
  text(cr, "size of g: " + unit, left, height - 18, kProfileLabel);
  text(cr, "error / chunk scale", 8, top - 12, kProfileLabel);
  text(cr,
       "How far from " + props::to_string(group) + "-equivariant (" +
           std::to_string(profiles.front().scenes) + " scenes per size)",
       left, 30, 15.0, Align::left, true);

  double legend_y = top + 12;
  const double dash[] = {6.0, 4.0};
  for (std::size_t s = 0; s < profiles.size(); ++s) {
    const props::Profile& p = profiles[s];
    const auto& c = kProfileColours[s % kProfileColours.size()];
    const auto colour = [&] { set_rgb(cr, c[0], c[1], c[2]); };
    colour();
    // The lines first, then the marks on top of them; each line a path of its own (a text
    // leaves its end as the current point, which a first line_to would join).
    cairo_set_line_width(cr, 2.0);
    cairo_new_path(cr);
    for (std::size_t k = 0; k < p.points.size(); ++k)
      cairo_line_to(cr, x_of(p.points[k].size), y_of(p.points[k].pointwise.median));
    cairo_stroke(cr);
    cairo_set_dash(cr, dash, 2, 0.0);
    cairo_new_path(cr);
    for (std::size_t k = 0; k < p.points.size(); ++k)
      if (p.points[k].distribution)
        cairo_line_to(cr, x_of(p.points[k].size), y_of(p.points[k].distribution->median));
    cairo_stroke(cr);
    cairo_set_dash(cr, dash, 0, 0.0);
    cairo_set_line_width(cr, 1.0);
    for (const props::ProfilePoint& point : p.points) {
      const double x = x_of(point.size);
      circle(x, y_of(point.pointwise.median), 4, true);
      circle(x, y_of(point.pointwise.max), 3, false);
      if (point.distribution) {
        cairo_rectangle(cr, x - 4, y_of(point.distribution->median) - 4, 8, 8);
        cairo_stroke(cr);
      }
    }
    const double key_x = right + 15;
    cairo_set_line_width(cr, 2.0);
    line(key_x, legend_y, key_x + 22, legend_y);
    circle(key_x + 11, legend_y, 4, true);
    set_rgb(cr, 20, 20, 20);
    for (const std::string& label : label_of(p)) {
      text(cr, label, key_x + 30, legend_y + 4, kProfileLegend);
      legend_y += 17;
    }
    legend_y += 5;
  }
  const double kx = right + 15, ky = legend_y + 14;
  set_rgb(cr, 90, 90, 90);
  cairo_set_line_width(cr, 1.0);
  circle(kx + 11, ky, 4, true);
  circle(kx + 11, ky + 22, 3, false);
  cairo_rectangle(cr, kx + 7, ky + 40, 8, 8);
  cairo_stroke(cr);
  set_rgb(cr, 20, 20, 20);
  text(cr, "pointwise, median", kx + 30, ky + 4, kProfileLegend);
  text(cr, "pointwise, max", kx + 30, ky + 26, kProfileLegend);
  text(cr, "in distribution, median", kx + 30, ky + 48, kProfileLegend);
  text(cr, "on 1e-16: 1e-16 or below (0 too)", kx, ky + 75, kProfileLegend);
  return canvas.image();
}

void write_profiles_png(const std::string& path, const std::vector<props::Profile>& profiles) {
  sim::write_png(path, draw_profiles(profiles));
}

}  // namespace handcentric::experiments
