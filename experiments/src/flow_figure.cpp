#include "handcentric/experiments/flow_figure.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/sim/collision.hpp"
#include "handcentric/sim/demos.hpp"
#include "handcentric/sim/expert.hpp"
#include "handcentric/sim/canvas.hpp"
#include "handcentric/sim/scenes.hpp"

namespace handcentric::experiments {
namespace {

using sim::Align;
using sim::set_rgb;
using sim::text;

constexpr double kPi = 3.14159265358979323846;
// The policy's own chunk shape (PolicyConfig's defaults): no history, K = 16.
constexpr int kHistory = 0;
constexpr int kChunk = 16;

Eigen::Vector2d first_position(const Eigen::VectorXd& actions) {
  return actions.head<2>();
}

// A column's plotting window: every point of both rows and the noise, with a margin, square.
struct Window {
  Eigen::Vector2d centre;
  double half_width;
};

Window window_of(const FlowColumn& column, const std::vector<Eigen::Vector2d>& noise) {
  Eigen::Vector2d lo = column.original.cwiseMin(column.transformed);
  Eigen::Vector2d hi = column.original.cwiseMax(column.transformed);
  for (const auto& p : column.training_positions) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  for (const auto& p : noise) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const double half = 0.55 * std::max({hi.x() - lo.x(), hi.y() - lo.y(), 1.0});
  return {0.5 * (lo + hi), half};
}

// Layout of draw_flow_figure, in pixels.
constexpr int kLeft = 110, kTop = 78, kGap = 20, kCaption = 46;

}  // namespace

PanelBox flow_panel_box(int column, int row, int panel_size) {
  return {kLeft + column * (panel_size + kGap), kTop + row * (panel_size + kCaption), panel_size};
}

void FlowFigureOptions::validate() const {
  if (demos < 1 || demos > 1000) {
    throw InvalidArgument("flow figure: demos = " + std::to_string(demos) +
                          " is outside [1, 1000]");
  }
  if (noise_draws < 1 || noise_draws > 200) {
    throw InvalidArgument("flow figure: noise_draws = " + std::to_string(noise_draws) +
                          " is outside [1, 200]");
  }
  if (!std::isfinite(rotation_deg) || !std::isfinite(translation_x) ||
      !std::isfinite(translation_y)) {
    throw InvalidArgument(
        "flow figure: the transform g needs finite numbers (rotation_deg, translation_x/_y)");
  }
}

FlowFigure compute_flow_figure(const FlowFigureOptions& options) {
  options.validate();
  const sim::CollisionChecker checker;
  const auto task_scenes =
      sim::sample_scenes(sim::SceneDistribution::train(), options.demos, options.seed);
  const sim::ExpertRun run = sim::expert_demos(task_scenes, options.seed, checker);
  if (run.demos.empty())
    throw Error("flow figure: the expert solved none of the " + std::to_string(options.demos) +
                " scenes");
  const std::vector<Scene> scenes =
      sim::training_scenes(run.demos, kHistory, kChunk, 0, checker.geometry());

  FlowFigure figure;
  figure.g = RigidTransform::planar(options.rotation_deg * kPi / 180.0, options.translation_x,
                                    options.translation_y);
  std::mt19937_64 rng(options.seed);
  for (int i = 0; i < options.noise_draws; ++i) {
    const double x = standard_normal(rng);
    figure.noise.emplace_back(x, standard_normal(rng));
  }
  // The chunk shown: the first demo's first step, where the whole insertion lies ahead.
  const Scene& chosen = scenes.front();
  const Scene moved = figure.g * chosen;
  for (const std::string name : {"absolute", "relative", "hand_centric"}) {
    const auto representation = make_representation(name);
    FlowColumn column;
    column.representation = name;
    column.training_positions.reserve(scenes.size());
    for (const Scene& scene : scenes)
      column.training_positions.push_back(first_position(representation->encode_actions(scene)));
    const Eigen::VectorXd a_original = representation->encode_actions(chosen);
    const Eigen::VectorXd a_moved = representation->encode_actions(moved);
    column.original = first_position(a_original);
    column.transformed = first_position(a_moved);
    column.a1_change = (a_moved.head<6>() - a_original.head<6>()).norm();
    figure.columns.push_back(std::move(column));
  }
  return figure;
}

sim::Image draw_flow_figure(const FlowFigure& figure, int panel_size) {
  if (figure.columns.empty()) throw InvalidArgument("draw_flow_figure: no columns to draw");
  if (panel_size < 160 || panel_size > 2000) {
    throw InvalidArgument("draw_flow_figure: panel_size " + std::to_string(panel_size) +
                          " is outside [160, 2000]");
  }
  const int columns = static_cast<int>(figure.columns.size());
  const int width = kLeft + columns * (panel_size + kGap);
  const int height = kTop + 2 * (panel_size + kCaption) + 40;
  const sim::Canvas canvas(width, height);
  cairo_t* cr = canvas.cr();
  const auto blue = [cr] { set_rgb(cr, 86, 140, 210); };
  const auto orange = [cr] { set_rgb(cr, 230, 120, 0); };
  const auto grey = [cr] { set_rgb(cr, 150, 150, 150); };
  const auto ink = [cr] { set_rgb(cr, 20, 20, 20); };
  const auto dot = [cr](const Eigen::Vector2d& at, double r) {
    cairo_new_sub_path(cr);
    cairo_arc(cr, at.x(), at.y(), r, 0.0, 2.0 * kPi);
    cairo_fill(cr);
  };
  const auto segment = [cr](const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
    cairo_move_to(cr, from.x(), from.y());
    cairo_line_to(cr, to.x(), to.y());
  };
  ink();
  text(cr,
       "Fig. 3: flow of a_1's position towards one chunk's a_1 (orange) and all training a_1 "
       "(blue)",
       kLeft, 28, 15.0, Align::left, true);
  text(cr,
       "x, y in cm, each column at one scale; + marks the origin of the representation's frame; "
       "grey dots: noise draws",
       kLeft, 52, 12.0);
  const char* row_names[2] = {"chunk", "g * chunk"};
  for (int row = 0; row < 2; ++row) {
    const PanelBox box = flow_panel_box(0, row, panel_size);
    text(cr, row_names[row], 10, box.y + panel_size / 2, 14.0);
  }
  for (int c = 0; c < columns; ++c) {
    const FlowColumn& column = figure.columns[static_cast<std::size_t>(c)];
    const Window window = window_of(column, figure.noise);
    for (int row = 0; row < 2; ++row) {
      const PanelBox box = flow_panel_box(c, row, panel_size);
      const int x0 = box.x, y0 = box.y;
      const auto px = [&](const Eigen::Vector2d& p) {
        const Eigen::Vector2d s = (p - window.centre) / (2.0 * window.half_width);
        return Eigen::Vector2d(x0 + std::round((0.5 + s.x()) * panel_size),
                               y0 + std::round((0.5 - s.y()) * panel_size));
      };
      grey();
      cairo_set_line_width(cr, 1.0);
      cairo_rectangle(cr, x0 + 0.5, y0 + 0.5, panel_size, panel_size);
      cairo_stroke(cr);
      // The origin of the representation's frame (the world's, or the hand's now).
      const Eigen::Vector2d origin = px(Eigen::Vector2d::Zero());
      segment(origin - Eigen::Vector2d(6, 0), origin + Eigen::Vector2d(6, 0));
      segment(origin - Eigen::Vector2d(0, 6), origin + Eigen::Vector2d(0, 6));
      cairo_stroke(cr);
      blue();
      for (const auto& p : column.training_positions) dot(px(p), 2.0);
      const Eigen::Vector2d target = row == 0 ? column.original : column.transformed;
      for (const auto& eps : figure.noise) {
        grey();
        dot(px(eps), 3.0);
        // An arrow 92% of the way to the target, its head 4% of its length (at least 4 px).
        const Eigen::Vector2d from = px(eps), to = px(eps + 0.92 * (target - eps));
        const Eigen::Vector2d back = from - to;
        orange();
        segment(from, to);
        if (back.norm() > 0.0) {
          const Eigen::Vector2d head = back.normalized() * std::max(4.0, 0.04 * back.norm());
          const Eigen::Vector2d side(-head.y(), head.x());
          segment(to, to + head + 0.5 * side);
          segment(to, to + head - 0.5 * side);
        }
        cairo_stroke(cr);
      }
      orange();
      dot(px(target), 6.0);
      ink();
      if (row == 0) text(cr, column.representation, x0 + 5, y0 - 8, 15.0);
    }
    const PanelBox bottom = flow_panel_box(c, 1, panel_size);
    const int y_caption = bottom.y + panel_size + 22;
    ink();
    std::string change = "|a_1(g*chunk) - a_1(chunk)| = ";  // appends (GCC 12 -Wrestrict)
    change += format_significant(column.a1_change, 2);
    text(cr, change, bottom.x, y_caption, 13.0);
    if (column.a1_change < 1e-9) {
      set_rgb(cr, 40, 150, 60);
    } else {
      set_rgb(cr, 200, 40, 40);
    }
    text(cr, column.a1_change < 1e-9 ? "flow unchanged by g" : "flow moved by g", bottom.x,
         y_caption + 20, 13.0);
  }
  return canvas.image();
}

void write_flow_figure_png(const std::string& path, const FlowFigure& figure) {
  sim::write_png(path, draw_flow_figure(figure));
}

}  // namespace handcentric::experiments
