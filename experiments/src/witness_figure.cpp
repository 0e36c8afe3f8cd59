#include "handcentric/experiments/witness_figure.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <vector>

#include "handcentric/core/errors.hpp"

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

std::string number(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", value);
  return text;
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

std::string witness_svg(const Scene& scene, const RigidTransform& g, int width, int height) {
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
  int a = 0, b = 1;  // x and y unless z spreads more than one of them
  if (spread.z() > std::min(spread.x(), spread.y())) {
    if (spread.x() < spread.y())
      a = 2;
    else
      b = 2;
    if (a > b) std::swap(a, b);
  }
  const char* axis_names[] = {"x", "y", "z"};
  const double lo_x = lo[a], lo_y = lo[b], hi_x = hi[a], hi_y = hi[b];
  // One scale for both axes (the picture is not distorted), and a margin for the markers and
  // the legend.
  const double margin = 18.0, legend = 34.0;
  const double span = std::max({hi_x - lo_x, hi_y - lo_y, 1e-9});
  const double scale = std::min((width - 2 * margin) / span, (height - 2 * margin - legend) / span);
  const auto sx = [&](const Eigen::Vector3d& p) { return number(margin + (p[a] - lo_x) * scale); };
  const auto sy = [&](const Eigen::Vector3d& p) {
    return number(height - margin - (p[b] - lo_y) * scale);
  };

  std::ostringstream svg;
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
      << "\" viewBox=\"0 0 " << width << " " << height << "\" font-family=\"sans-serif\" "
      << "font-size=\"11\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  const auto draw = [&](const Drawn& drawn, const char* colour, bool dashed) {
    std::string path;
    for (const auto* list : {&drawn.history, &drawn.chunk}) {
      // The history runs from T_0 backwards; drawn from the oldest pose to the last of the chunk.
      std::vector<Eigen::Vector3d> ordered = *list;
      if (list == &drawn.history) std::reverse(ordered.begin(), ordered.end());
      for (const Eigen::Vector3d& p : ordered)
        path += (path.empty() ? "M" : " L") + sx(p) + "," + sy(p);
    }
    svg << "<path d=\"" << path << "\" fill=\"none\" stroke=\"" << colour
        << "\" stroke-width=\"1.5\"" << (dashed ? " stroke-dasharray=\"5,3\"" : "") << "/>\n";
    const auto marker = [&](const Eigen::Vector3d& p, double r, bool filled) {
      const std::string fill = filled ? colour : "white";
      if (dashed) {
        svg << "<rect x=\"" << number(margin + (p[a] - lo_x) * scale - r) << "\" y=\""
            << number(height - margin - (p[b] - lo_y) * scale - r) << "\" width=\"" << number(2 * r)
            << "\" height=\"" << number(2 * r) << "\" fill=\"" << fill << "\" stroke=\"" << colour
            << "\"/>\n";
      } else {
        svg << "<circle cx=\"" << sx(p) << "\" cy=\"" << sy(p) << "\" r=\"" << number(r)
            << "\" fill=\"" << fill << "\" stroke=\"" << colour << "\"/>\n";
      }
    };
    for (const Eigen::Vector3d& p : drawn.chunk) marker(p, 2.0, false);
    marker(drawn.history.front(), 4.5, true);  // T_0
    for (const Eigen::Vector3d& p : drawn.points) marker(p, 3.5, true);
  };
  draw(before, "#1f5fa8", false);
  draw(after, "#c0561b", true);
  svg << "<text x=\"" << margin << "\" y=\"14\">solid, circles: s; dashed, squares: g&#183;s"
      << "</text>\n<text x=\"" << margin
      << "\" y=\"28\">big mark: T_0; path: history, then the chunk; axes (" << axis_names[a] << ", "
      << axis_names[b] << ")</text>\n"
      << "</svg>\n";
  return svg.str();
}

}  // namespace handcentric::experiments
