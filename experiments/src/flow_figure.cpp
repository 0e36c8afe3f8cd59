#include "handcentric/experiments/flow_figure.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

#include "drawing.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/sim/collision.hpp"
#include "handcentric/sim/demos.hpp"
#include "handcentric/sim/expert.hpp"
#include "handcentric/sim/scenes.hpp"

namespace handcentric::experiments {
namespace {

using drawing::rgb;
using drawing::text;

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
  cv::Mat canvas(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const cv::Scalar blue = rgb(86, 140, 210), orange = rgb(230, 120, 0), grey = rgb(150, 150, 150);
  text(
      canvas,
      "Fig. 3: flow of a_1's position towards one chunk's a_1 (orange) and all training a_1 (blue)",
      cv::Point(kLeft, 28), 0.6);
  text(canvas,
       "x, y in cm, each column at one scale; + marks the origin of the representation's frame; "
       "grey dots: noise draws",
       cv::Point(kLeft, 52), 0.45);
  const char* row_names[2] = {"chunk", "g * chunk"};
  for (int row = 0; row < 2; ++row) {
    const PanelBox box = flow_panel_box(0, row, panel_size);
    text(canvas, row_names[row], cv::Point(10, box.y + panel_size / 2), 0.55);
  }
  for (int c = 0; c < columns; ++c) {
    const FlowColumn& column = figure.columns[static_cast<std::size_t>(c)];
    const Window window = window_of(column, figure.noise);
    for (int row = 0; row < 2; ++row) {
      const PanelBox box = flow_panel_box(c, row, panel_size);
      const int x0 = box.x, y0 = box.y;
      const auto px = [&](const Eigen::Vector2d& p) {
        const Eigen::Vector2d s = (p - window.centre) / (2.0 * window.half_width);
        return cv::Point(x0 + static_cast<int>(std::lround((0.5 + s.x()) * panel_size)),
                         y0 + static_cast<int>(std::lround((0.5 - s.y()) * panel_size)));
      };
      cv::rectangle(canvas, cv::Point(x0, y0), cv::Point(x0 + panel_size, y0 + panel_size), grey,
                    1);
      // The origin of the representation's frame (the world's, or the hand's now).
      const cv::Point origin = px(Eigen::Vector2d::Zero());
      cv::drawMarker(canvas, origin, grey, cv::MARKER_CROSS, 12, 1);
      for (const auto& p : column.training_positions)
        cv::circle(canvas, px(p), 2, blue, cv::FILLED, cv::LINE_AA);
      const Eigen::Vector2d target = row == 0 ? column.original : column.transformed;
      for (const auto& eps : figure.noise) {
        cv::circle(canvas, px(eps), 3, grey, cv::FILLED, cv::LINE_AA);
        cv::arrowedLine(canvas, px(eps), px(eps + 0.92 * (target - eps)), orange, 1, cv::LINE_AA, 0,
                        0.04);
      }
      cv::circle(canvas, px(target), 6, orange, cv::FILLED, cv::LINE_AA);
      if (row == 0) text(canvas, column.representation, cv::Point(x0 + 5, y0 - 8), 0.6);
    }
    char line[128];
    const PanelBox bottom = flow_panel_box(c, 1, panel_size);
    const int y_caption = bottom.y + panel_size + 22;
    std::snprintf(line, sizeof line, "|a_1(g*chunk) - a_1(chunk)| = %.2g", column.a1_change);
    text(canvas, line, cv::Point(bottom.x, y_caption), 0.5);
    text(canvas, column.a1_change < 1e-9 ? "flow unchanged by g" : "flow moved by g",
         cv::Point(bottom.x, y_caption + 20), 0.5,
         column.a1_change < 1e-9 ? rgb(40, 150, 60) : rgb(200, 40, 40));
  }
  return drawing::to_image(canvas);
}

void write_flow_figure_png(const std::string& path, const FlowFigure& figure) {
  sim::write_png(path, draw_flow_figure(figure));
}

}  // namespace handcentric::experiments
