#include "handcentric/experiments/profile_plot.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <opencv2/imgproc.hpp>

#include "drawing.hpp"
#include "handcentric/core/errors.hpp"

namespace handcentric::experiments {
namespace {

using drawing::dashed;
using drawing::rgb;
using drawing::text;

// Paul Tol's "bright" scheme (colour-blind safe), one per profile in order.
const cv::Scalar kProfileColours[] = {rgb(68, 119, 170), rgb(238, 102, 119), rgb(34, 136, 51),
                                      rgb(204, 187, 68), rgb(102, 204, 238), rgb(170, 51, 119),
                                      rgb(60, 60, 60)};

constexpr double kLowestDecade = -16.0;
// Pixels between the axes' box and the outermost grid line, so that a mark on the first or last
// size, or on the bottom decade, stays inside the box.
constexpr int kInset = 12;

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
  cv::Mat canvas(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const int left = 80, right = width - 290, top = 60, bottom = height - 60;
  const auto x_of = [&](double size) {
    const double x = c8 ? size * 180.0 / std::numbers::pi : std::log10(size);
    return static_cast<int>(
        std::lround(left + kInset + (right - left - 2 * kInset) * (x - ax_lo) / (ax_hi - ax_lo)));
  };
  const auto y_of = [&](double value) {
    const double y = value > 0.0 && std::isfinite(value)
                         ? std::clamp(std::log10(value), ay_lo, ay_hi)
                         : (std::isfinite(value) ? ay_lo : ay_hi);
    return static_cast<int>(
        std::lround(bottom - kInset - (bottom - top - 2 * kInset) * (y - ay_lo) / (ay_hi - ay_lo)));
  };
  // Grid and ticks.
  const int y_step = ay_hi - ay_lo > 10 ? 2 : 1;
  for (int d = static_cast<int>(ay_lo); d <= static_cast<int>(ay_hi); d += y_step) {
    const int y = y_of(std::pow(10.0, d));
    cv::line(canvas, {left, y}, {right, y}, rgb(225, 225, 225), 1);
    text(canvas, "1e" + std::to_string(d), {left - 52, y + 5}, 0.45);
  }
  if (c8) {
    for (int deg = 0; deg <= static_cast<int>(ax_hi); deg += 45) {
      const int x = x_of(deg * std::numbers::pi / 180.0);
      cv::line(canvas, {x, top}, {x, bottom}, rgb(200, 200, 235), 1);
      text(canvas, std::to_string(deg), {x - 10, bottom + 20}, 0.45);
    }
  } else {
    for (int d = static_cast<int>(ax_lo); d <= static_cast<int>(ax_hi); ++d) {
      const int x = x_of(std::pow(10.0, d));
      cv::line(canvas, {x, top}, {x, bottom}, rgb(225, 225, 225), 1);
      text(canvas, "1e" + std::to_string(d), {x - 14, bottom + 20}, 0.45);
    }
  }
  cv::rectangle(canvas, {left, top}, {right, bottom}, rgb(20, 20, 20), 1);
  const std::string unit =
      c8 ? "deg about z (C8's elements: the blue lines)" : props::profile_unit(group);
  text(canvas, "size of g: " + unit, {left, height - 18}, 0.5);
  text(canvas, "error / chunk scale", {8, top - 12}, 0.5);
  text(canvas,
       "How far from " + props::to_string(group) + "-equivariant (" +
           std::to_string(profiles.front().scenes) + " scenes per size)",
       {left, 30}, 0.65);

  int legend_y = top + 12;
  for (std::size_t s = 0; s < profiles.size(); ++s) {
    const props::Profile& p = profiles[s];
    const cv::Scalar colour = kProfileColours[s % std::size(kProfileColours)];
    cv::Point previous, previous_law;
    for (std::size_t k = 0; k < p.points.size(); ++k) {
      const props::ProfilePoint& point = p.points[k];
      const cv::Point at(x_of(point.size), y_of(point.pointwise.median));
      if (k > 0) cv::line(canvas, previous, at, colour, 2, cv::LINE_AA);
      cv::circle(canvas, at, 4, colour, cv::FILLED, cv::LINE_AA);
      cv::circle(canvas, {at.x, y_of(point.pointwise.max)}, 3, colour, 1, cv::LINE_AA);
      previous = at;
      if (point.distribution) {
        const cv::Point law(x_of(point.size), y_of(point.distribution->median));
        if (k > 0) dashed(canvas, previous_law, law, colour);
        cv::rectangle(canvas, law - cv::Point(4, 4), law + cv::Point(4, 4), colour, 1, cv::LINE_AA);
        previous_law = law;
      }
    }
    const cv::Point key(right + 15, legend_y);
    cv::line(canvas, key, key + cv::Point(22, 0), colour, 2, cv::LINE_AA);
    cv::circle(canvas, key + cv::Point(11, 0), 4, colour, cv::FILLED, cv::LINE_AA);
    for (const std::string& line : label_of(p)) {
      text(canvas, line, {key.x + 30, legend_y + 5}, 0.42);
      legend_y += 17;
    }
    legend_y += 5;
  }
  const cv::Point key(right + 15, legend_y + 14);
  const cv::Scalar grey = rgb(90, 90, 90);
  cv::circle(canvas, key + cv::Point(11, 0), 4, grey, cv::FILLED, cv::LINE_AA);
  text(canvas, "pointwise, median", key + cv::Point(30, 5), 0.42);
  cv::circle(canvas, key + cv::Point(11, 22), 3, grey, 1, cv::LINE_AA);
  text(canvas, "pointwise, max", key + cv::Point(30, 27), 0.42);
  cv::rectangle(canvas, key + cv::Point(7, 40), key + cv::Point(15, 48), grey, 1, cv::LINE_AA);
  text(canvas, "in distribution, median", key + cv::Point(30, 49), 0.42);
  text(canvas, "on 1e-16: 1e-16 or below (0 too)", key + cv::Point(0, 75), 0.42);
  return drawing::to_image(canvas);
}

void write_profiles_png(const std::string& path, const std::vector<props::Profile>& profiles) {
  sim::write_png(path, draw_profiles(profiles));
}

}  // namespace handcentric::experiments
