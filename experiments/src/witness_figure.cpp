#include "handcentric/experiments/witness_figure.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/sim/canvas.hpp"

namespace handcentric::experiments {
namespace {

struct Drawn {
  std::vector<Eigen::Vector3d> history, chunk, points;
};

Drawn positions(const Scene& scene) {
  Drawn out;
  for (const auto& pose : scene.world_T_hand_history) out.history.push_back(pose.translation());
  for (const auto& pose : scene.world_T_hand_chunk) out.chunk.push_back(pose.translation());
  out.points = scene.world_points;
  return out;
}

// Margin for the markers, and room at the top for the legend, in px.
constexpr double kMargin = 18.0, kLegend = 34.0;

// One scene's marks, drawn in `colour` (0-255 RGB): solid with circles, or dashed with squares.
void draw_marks(cairo_t* cr, const WitnessMarks& marks, const std::array<int, 3>& colour,
                bool dashed) {
  const auto set_colour = [&] { sim::set_rgb(cr, colour[0], colour[1], colour[2]); };
  set_colour();
  cairo_set_line_width(cr, 1.5);
  const double dash[] = {5.0, 3.0};
  cairo_set_dash(cr, dash, dashed ? 2 : 0, 0.0);
  cairo_new_path(cr);
  for (const Eigen::Vector2d& p : marks.path) cairo_line_to(cr, p.x(), p.y());
  cairo_stroke(cr);
  cairo_set_dash(cr, dash, 0, 0.0);
  cairo_set_line_width(cr, 1.0);
  const auto marker = [&](const Eigen::Vector2d& p, double r, bool filled) {
    cairo_new_sub_path(cr);
    if (dashed) {
      cairo_rectangle(cr, p.x() - r, p.y() - r, 2 * r, 2 * r);
    } else {
      cairo_arc(cr, p.x(), p.y(), r, 0.0, 2.0 * std::numbers::pi);
    }
    if (filled) {
      set_colour();
    } else {
      cairo_set_source_rgb(cr, 1.0, 1.0, 1.0);
    }
    cairo_fill_preserve(cr);
    set_colour();
    cairo_stroke(cr);
  };
  for (const Eigen::Vector2d& p : marks.chunk) marker(p, 2.0, false);
  marker(marks.t0, 4.5, true);
  for (const Eigen::Vector2d& p : marks.points) marker(p, 3.5, true);
}

}  // namespace

bool drawable(const Scene& scene) {
  if (scene.world_T_hand_history.empty()) return false;
  for (const auto& pose : scene.world_T_hand_history)
    if (!pose.translation().allFinite()) return false;
  for (const auto& pose : scene.world_T_hand_chunk)
    if (!pose.translation().allFinite()) return false;
  for (const auto& point : scene.world_points)
    if (!point.allFinite()) return false;
  return true;
}

WitnessPicture witness_picture(const Scene& scene, const RigidTransform& g, int width, int height) {
  if (!drawable(scene)) {
    throw InvalidArgument("witness figure: the scene has no hand pose or a non-finite position");
  }
  const Drawn before = positions(scene);
  const Drawn after = positions(g * scene);
  // The two axes along which the drawn positions spread most: a g along z shows from the side.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const Drawn* drawn : {&before, &after}) {
    for (const auto* list : {&drawn->history, &drawn->chunk, &drawn->points}) {
      for (const Eigen::Vector3d& p : *list) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
    }
  }
  const Eigen::Vector3d spread = hi - lo;
  WitnessPicture picture;
  int& a = picture.across;
  int& b = picture.up;  // x and y unless z spreads more than one of them
  if (spread.z() > std::min(spread.x(), spread.y())) {
    if (spread.x() < spread.y())
      a = 2;
    else
      b = 2;
    if (a > b) std::swap(a, b);
  }
  // One scale for both axes (the picture is not distorted).
  const double span = std::max({hi[a] - lo[a], hi[b] - lo[b], 1e-9});
  const double scale =
      std::min((width - 2 * kMargin) / span, (height - 2 * kMargin - kLegend) / span);
  const auto px = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector2d(kMargin + (p[a] - lo[a]) * scale,
                           height - kMargin - (p[b] - lo[b]) * scale);
  };
  const auto marks_of = [&](const Drawn& drawn) {
    WitnessMarks marks;
    // The history runs from T_0 backwards; drawn from the oldest pose to the last of the chunk.
    for (auto it = drawn.history.rbegin(); it != drawn.history.rend(); ++it)
      marks.path.push_back(px(*it));
    for (const Eigen::Vector3d& p : drawn.chunk) {
      marks.path.push_back(px(p));
      marks.chunk.push_back(px(p));
    }
    marks.t0 = px(drawn.history.front());
    for (const Eigen::Vector3d& p : drawn.points) marks.points.push_back(px(p));
    return marks;
  };
  picture.s = marks_of(before);
  picture.g_s = marks_of(after);
  return picture;
}

std::string witness_svg(const Scene& scene, const RigidTransform& g, int width, int height) {
  const WitnessPicture picture = witness_picture(scene, g, width, height);
  const char* axis_names[] = {"x", "y", "z"};
  return sim::svg_drawing(
      width, height,
      [&](cairo_t* cr) {
        sim::white_page(cr, width, height);
        draw_marks(cr, picture.s, {31, 95, 168}, false);
        draw_marks(cr, picture.g_s, {192, 86, 27}, true);
        sim::set_rgb(cr, 20, 20, 20);
        sim::text(cr, "solid, circles: s; dashed, squares: g\u00b7s", kMargin, 14, 10.0);
        sim::text(cr,
                  std::string("big mark: T_0; path: history, then the chunk; axes (") +
                      axis_names[picture.across] + ", " + axis_names[picture.up] + ")",
                  kMargin, 28, 10.0);
      },
      sim::SvgUnit::px);
}

}  // namespace handcentric::experiments
