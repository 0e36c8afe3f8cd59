// OpenCV drawings of scenes, demos and rollouts (draw.hpp), captioned in Cairo text (canvas.hpp).
#include "handcentric/sim/draw.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/sim/canvas.hpp"

namespace handcentric::sim {
namespace {

constexpr int kMargin = 30;   // pixels around the content
constexpr int kCaption = 36;  // pixels of caption band at the top

cv::Scalar rgb(int r, int g, int b) {
  return cv::Scalar(b, g, r);
}  // OpenCV stores BGR
cv::Scalar rgb(const std::uint8_t (&c)[3]) {
  return rgb(c[0], c[1], c[2]);
}

/// World (cm, y up) to pixels: fits a bounding box into the canvas below the caption.
class View {
 public:
  View(double x0, double x1, double y0, double y1, int size) : size_(size) {
    const double span = std::max({x1 - x0, y1 - y0, 1.0});
    scale_ = (size - 2 * kMargin - kCaption) / span;
    cx_ = 0.5 * (x0 + x1);
    cy_ = 0.5 * (y0 + y1);
  }
  cv::Point px(const Eigen::Vector3d& p) const {
    return cv::Point(
        static_cast<int>(std::lround(0.5 * size_ + scale_ * (p.x() - cx_))),
        static_cast<int>(std::lround(0.5 * (size_ + kCaption) - scale_ * (p.y() - cy_))));
  }
  double scale() const { return scale_; }

 private:
  int size_;
  double scale_, cx_, cy_;
};

std::vector<cv::Point> outline(const View& view, const RigidTransform& world_T_frame,
                               const Box& box) {
  const Eigen::Vector3d corners[4] = {
      {box.x0, box.y0, 0}, {box.x1, box.y0, 0}, {box.x1, box.y1, 0}, {box.x0, box.y1, 0}};
  std::vector<cv::Point> points;
  for (const auto& c : corners) points.push_back(view.px(world_T_frame * c));
  return points;
}

/// Bounding box of the hole and the given hand poses (with the peg's reach).
View fit(const std::vector<RigidTransform>& world_T_holes,
         const std::vector<RigidTransform>& world_T_hands, const PegHoleGeometry& geometry,
         int size) {
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  const auto grow = [&](const Eigen::Vector3d& p) {
    x0 = std::min(x0, p.x()), x1 = std::max(x1, p.x()), y0 = std::min(y0, p.y()),
    y1 = std::max(y1, p.y());
  };
  for (const RigidTransform& T : world_T_holes) {
    for (const Box& wall : geometry.hole_walls()) {
      for (const double x : {wall.x0, wall.x1})
        for (const double y : {wall.y0, wall.y1}) grow(T * Eigen::Vector3d(x, y, 0));
    }
  }
  for (const RigidTransform& T : world_T_hands) {
    for (const Eigen::Vector3d& c : geometry.peg_corners()) grow(T * c);
  }
  const double pad = 1.0;
  return View(x0 - pad, x1 + pad, y0 - pad, y1 + pad, size);
}

void draw_hole(cv::Mat& canvas, const View& view, const RigidTransform& world_T_hole,
               const PegHoleGeometry& geometry) {
  for (const Box& wall : geometry.hole_walls()) {
    const auto poly = outline(view, world_T_hole, wall);
    cv::fillConvexPoly(canvas, poly, rgb(150, 150, 150), cv::LINE_AA);
    cv::polylines(canvas, poly, true, rgb(90, 90, 90), 1, cv::LINE_AA);
  }
  // the hole's +y axis, out of the opening
  cv::line(canvas, view.px(world_T_hole * Eigen::Vector3d(0, 0, 0)),
           view.px(world_T_hole * Eigen::Vector3d(0, 3, 0)), rgb(120, 120, 120), 1, cv::LINE_AA);
  for (const Eigen::Vector3d& corner : geometry.opening_corners()) {
    cv::circle(canvas, view.px(world_T_hole * corner), 4, rgb(255, 140, 0), cv::FILLED,
               cv::LINE_AA);
  }
}

void check_size(int size) {
  if (size < 64 || size > 4096)
    throw InvalidArgument("image size must be in [64, 4096] pixels, got " + std::to_string(size));
}

// The drawing with its caption at the top left (Cairo text).
Image captioned(const cv::Mat& bgr, const std::string& caption) {
  cv::Mat rgb_mat;
  cv::cvtColor(bgr, rgb_mat, cv::COLOR_BGR2RGB);
  Image image;
  image.width = rgb_mat.cols;
  image.height = rgb_mat.rows;
  image.rgb.assign(rgb_mat.data, rgb_mat.data + rgb_mat.total() * 3);
  return labelled(image, {{caption, 10.0, 24.0, 15.0}});
}

cv::Mat blank(int size) {
  return cv::Mat(size, size, CV_8UC3, cv::Scalar(255, 255, 255));
}

}  // namespace

Image draw_scene(const TaskScene& scene, const PegHoleGeometry& geometry, int size) {
  check_size(size);
  cv::Mat canvas = blank(size);
  const View view = fit({scene.world_T_hole}, {scene.world_T_hand_start}, geometry, size);
  draw_hole(canvas, view, scene.world_T_hole, geometry);
  cv::polylines(canvas, outline(view, scene.world_T_hand_start, geometry.peg_in_hand()), true,
                rgb(30, 90, 220), 2, cv::LINE_AA);
  cv::circle(canvas, view.px(scene.world_T_hand_start * Eigen::Vector3d::Zero()), 3,
             rgb(30, 90, 220), cv::FILLED);
  const Eigen::Vector3d q = planar_coordinates(scene.world_T_hole);
  return captioned(canvas, "scene: hole at (" + format_fixed(q(1), 1) + ", " +
                               format_fixed(q(2), 1) + ") cm, angle " +
                               format_fixed(q(0) * 180.0 / 3.14159265358979, 1) +
                               " deg; peg start in blue");
}

Image draw_demos(const std::vector<Demo>& demos, const PegHoleGeometry& geometry, int size) {
  check_size(size);
  cv::Mat canvas = blank(size);
  std::vector<std::vector<RigidTransform>> hole_T_hands;
  std::vector<RigidTransform> all;
  for (const Demo& demo : demos) {
    std::vector<RigidTransform> path;
    for (const RigidTransform& world_T_hand : demo.world_T_hand)
      path.push_back(demo.world_T_hole.inverse_compose(world_T_hand));
    all.insert(all.end(), path.begin(), path.end());
    hole_T_hands.push_back(std::move(path));
  }
  const View view = fit({RigidTransform()}, all, geometry, size);
  for (std::size_t d = 0; d < hole_T_hands.size(); ++d) {
    cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(static_cast<double>((d * 47) % 180), 200, 200));
    cv::Mat bgr;
    cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
    const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
    const cv::Scalar colour(c[0], c[1], c[2]);
    const auto& path = hole_T_hands[d];
    for (std::size_t t = 0; t < path.size(); t += 6) {
      cv::polylines(canvas, outline(view, path[t], geometry.peg_in_hand()), true, colour, 1,
                    cv::LINE_AA);
    }
    std::vector<cv::Point> line;
    for (const RigidTransform& T : path) line.push_back(view.px(T * Eigen::Vector3d::Zero()));
    cv::polylines(canvas, line, false, colour, 2, cv::LINE_AA);
  }
  draw_hole(canvas, view, RigidTransform(), geometry);
  return captioned(canvas, std::to_string(demos.size()) +
                               " demos in the hole frame: hand paths, peg every 6 steps");
}

Image draw_rollout(const TaskScene& scene, const Rollout& rollout, const PegHoleGeometry& geometry,
                   int size) {
  check_size(size);
  cv::Mat canvas = blank(size);
  const View view = fit({scene.world_T_hole}, rollout.world_T_hand, geometry, size);
  draw_hole(canvas, view, scene.world_T_hole, geometry);
  const std::size_t n = rollout.world_T_hand.size();
  for (std::size_t t = 0; t < n; ++t) {
    const double f =
        n > 1 ? static_cast<double>(t) / static_cast<double>(n - 1) : 1.0;  // light to dark blue
    const cv::Scalar colour = rgb(static_cast<int>(190 - 160 * f), static_cast<int>(210 - 130 * f),
                                  245 - static_cast<int>(40 * f));
    cv::polylines(canvas, outline(view, rollout.world_T_hand[t], geometry.peg_in_hand()), true,
                  colour, 1, cv::LINE_AA);
  }
  std::vector<cv::Point> line;
  for (const RigidTransform& T : rollout.world_T_hand)
    line.push_back(view.px(T * Eigen::Vector3d::Zero()));
  cv::polylines(canvas, line, false, rgb(30, 60, 160), 1, cv::LINE_AA);
  const cv::Scalar final_colour = rollout.outcome == Outcome::success     ? rgb(kSuccessRgb)
                                  : rollout.outcome == Outcome::collision ? rgb(kCollisionRgb)
                                                                          : rgb(110, 110, 110);
  const auto last = outline(view, rollout.world_T_hand.back(), geometry.peg_in_hand());
  cv::fillConvexPoly(canvas, last, final_colour);  // no anti-aliasing: tests count these pixels
  return captioned(canvas, outcome_name(rollout.outcome) + " after " +
                               std::to_string(rollout.steps) + " steps, " +
                               std::to_string(rollout.replans) + " replans, " +
                               std::to_string(rollout.clipped) + " clipped");
}

}  // namespace handcentric::sim
