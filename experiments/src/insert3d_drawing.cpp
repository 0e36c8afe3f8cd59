#include "handcentric/experiments/insert3d_drawing.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "drawing.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/experiments/insert3d_image.hpp"
#include "handcentric/sim/canvas.hpp"

namespace handcentric::experiments {
namespace {

namespace insert3d = sim::insert3d;
using drawing::rgb;

constexpr int kViewWidth = 760;
constexpr int kViewHeight = 640;
constexpr int kDepthScale = 8;

// A pinhole looking at `target` from target + distance * direction, world +z up on the page.
struct ViewCamera {
  Eigen::Vector3d eye, right, up, forward;
  double focal = 900.0;

  ViewCamera(const Eigen::Vector3d& target, const Eigen::Vector3d& direction, double distance) {
    forward = -direction.normalized();
    eye = target - distance * forward;
    right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
    up = right.cross(forward);
  }

  cv::Point project(const Eigen::Vector3d& world_point) const {
    const Eigen::Vector3d v = world_point - eye;
    const double depth = std::max(1.0, v.dot(forward));
    return {static_cast<int>(std::lround(kViewWidth / 2.0 + focal * v.dot(right) / depth)),
            static_cast<int>(std::lround(kViewHeight / 2.0 - focal * v.dot(up) / depth))};
  }
};

// The 12 edges of a box given in `frame_T_box` coordinates by world_T_frame.
void draw_box(cv::Mat& canvas, const ViewCamera& view, const RigidTransform& world_T_frame,
              const insert3d::Box3& box, const cv::Scalar& colour, int thickness) {
  std::array<cv::Point, 8> corners;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d local((i & 1) ? box.max.x() : box.min.x(),
                                (i & 2) ? box.max.y() : box.min.y(),
                                (i & 4) ? box.max.z() : box.min.z());
    corners[static_cast<std::size_t>(i)] = view.project(world_T_frame * local);
  }
  for (int i = 0; i < 8; ++i) {
    for (int bit : {1, 2, 4}) {
      if ((i & bit) == 0) {
        cv::line(canvas, corners[static_cast<std::size_t>(i)],
                 corners[static_cast<std::size_t>(i | bit)], colour, thickness, cv::LINE_AA);
      }
    }
  }
}

// The depth image, enlarged `scale` times, near bright: depth d maps to 255 (1 - d / max_range).
cv::Mat depth_panel(const CameraImage& image, double max_range, int scale = kDepthScale) {
  cv::Mat panel(image.height * scale, image.width * scale, CV_8UC3);
  for (int row = 0; row < image.height; ++row) {
    for (int col = 0; col < image.width; ++col) {
      const double shade = 255.0 * std::clamp(1.0 - image.depth_at(row, col) / max_range, 0.0, 1.0);
      const cv::Scalar grey(shade, shade, shade);
      cv::rectangle(panel, cv::Rect(col * scale, row * scale, scale, scale), grey, cv::FILLED);
    }
  }
  return panel;
}

// The normals channels of `image` (normals_from_depth): red (1 + x) / 2, green (1 + y) / 2 of the
// normal in the camera frame, blue a constant half, black where no normal is seen.
cv::Mat normals_panel(const CameraImage& image, const PinholeCamera& camera, int scale) {
  const std::vector<Eigen::Vector3d> normals = normals_from_depth(image, camera);
  cv::Mat panel(image.height * scale, image.width * scale, CV_8UC3, cv::Scalar(0, 0, 0));
  for (int row = 0; row < image.height; ++row) {
    for (int col = 0; col < image.width; ++col) {
      const Eigen::Vector3d& n = normals[static_cast<std::size_t>(row) * image.width + col];
      if (n.isZero()) continue;
      const cv::Scalar colour = rgb(static_cast<int>(std::lround(127.5 * (1.0 + n.x()))),
                                    static_cast<int>(std::lround(127.5 * (1.0 + n.y()))), 128);
      cv::rectangle(panel, cv::Rect(col * scale, row * scale, scale, scale), colour, cv::FILLED);
    }
  }
  return panel;
}

}  // namespace

sim::Image draw_insert3d_rollout(const insert3d::TaskScene& scene, const insert3d::Rollout& rollout,
                                 const std::string& caption,
                                 const insert3d::BladeSlotGeometry& geometry,
                                 const insert3d::DepthCamera& camera) {
  if (rollout.world_T_hand.empty())
    throw InvalidArgument("draw_insert3d_rollout: the rollout has no pose");
  geometry.validate();
  camera.validate();
  // Both panels, with 60 pixels above each and below the last, fit the view's height whatever
  // the camera: 8x a 32 x 24 image (the task's camera), 4x a 64 x 48 one.
  constexpr int kMargins = 3 * 60;
  const int scale =
      std::max(1, std::min(kDepthScale, (kViewHeight - kMargins) / (2 * camera.height)));
  const int panel_width = camera.width * scale;
  const int width = kViewWidth + panel_width + 40;
  // Taller than the view only for a camera of more than 230 rows.
  const int height = std::max(kViewHeight, kMargins + 2 * camera.height * scale);
  cv::Mat canvas(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  // Aimed between the slot's opening and the hand's start, so both are in view at any placement.
  const Eigen::Vector3d target =
      0.5 * (scene.world_T_slot.translation() + scene.world_T_hand_start.translation());
  const ViewCamera view(target, Eigen::Vector3d(1.0, -1.5, 1.0), 55.0);
  for (const insert3d::Box3& wall : geometry.slot_walls()) {
    draw_box(canvas, view, scene.world_T_slot, wall, rgb(110, 110, 110), 1);
  }
  for (const Eigen::Vector3d& corner : geometry.opening_corners()) {
    cv::circle(canvas, view.project(scene.world_T_slot * corner), 5, rgb(240, 140, 20), cv::FILLED,
               cv::LINE_AA);
  }
  const std::size_t n = rollout.world_T_hand.size();
  const std::size_t every = std::max<std::size_t>(1, n / 12);
  for (std::size_t t = 0; t + 1 < n; t += every) {
    const double s = n == 1 ? 0.0 : static_cast<double>(t) / static_cast<double>(n - 1);
    const cv::Scalar blue =
        rgb(static_cast<int>(170 - 140 * s), static_cast<int>(200 - 120 * s), 240);
    draw_box(canvas, view, rollout.world_T_hand[t], geometry.blade_in_hand(), blue, 1);
  }
  for (std::size_t t = 1; t < n; ++t) {
    cv::line(canvas, view.project(rollout.world_T_hand[t - 1].translation()),
             view.project(rollout.world_T_hand[t].translation()), rgb(30, 60, 200), 2, cv::LINE_AA);
  }
  const cv::Scalar last_colour =
      n == 1 ? rgb(30, 60, 200)
      : rollout.outcome == sim::Outcome::success
          ? rgb(sim::kSuccessRgb[0], sim::kSuccessRgb[1], sim::kSuccessRgb[2])
      : rollout.outcome == sim::Outcome::collision
          ? rgb(sim::kCollisionRgb[0], sim::kCollisionRgb[1], sim::kCollisionRgb[2])
          : rgb(120, 120, 120);
  draw_box(canvas, view, rollout.world_T_hand.back(), geometry.blade_in_hand(), last_colour, 3);
  std::vector<sim::Label> labels = {{caption, 12, kViewHeight - 16},
                                    {"fixed view from world (1, -1.5, 1), world z up", 12, 22}};

  const int x0 = kViewWidth + 20;
  const auto paste = [&](const RigidTransform& world_T_hand, int y, const std::string& label) {
    const cv::Mat panel =
        depth_panel(insert3d::render_depth(geometry, camera, world_T_hand, scene.world_T_slot),
                    camera.max_range, scale);
    panel.copyTo(canvas(cv::Rect(x0, y, panel.cols, panel.rows)));
    cv::rectangle(canvas, cv::Rect(x0, y, panel.cols, panel.rows), rgb(20, 20, 20), 1);
    labels.push_back({label, static_cast<double>(x0), y - 8.0});
  };
  paste(rollout.world_T_hand.front(), 60, "hand camera depth, first pose");
  if (n > 1) {
    paste(rollout.world_T_hand.back(), 60 + camera.height * scale + 60,
          "hand camera depth, last pose");
  }
  return sim::labelled(drawing::to_image(canvas), labels);
}

sim::Image draw_insert3d_camera_frames(const insert3d::TaskScene& scene,
                                       const insert3d::Rollout& rollout, int every, int columns,
                                       const insert3d::BladeSlotGeometry& geometry,
                                       const std::vector<insert3d::DepthCamera>& rig,
                                       bool normals) {
  if (rollout.world_T_hand.empty())
    throw InvalidArgument("draw_insert3d_camera_frames: the rollout has no pose");
  if (every < 1 || columns < 1) {
    throw InvalidArgument("draw_insert3d_camera_frames: every " + std::to_string(every) +
                          " and columns " + std::to_string(columns) + " must be >= 1");
  }
  if (rig.empty()) throw InvalidArgument("draw_insert3d_camera_frames: the rig has no camera");
  for (const insert3d::DepthCamera& camera : rig) camera.validate();
  std::vector<std::size_t> steps;
  for (std::size_t t = 0; t < rollout.world_T_hand.size(); t += static_cast<std::size_t>(every))
    steps.push_back(t);
  if (steps.back() + 1 != rollout.world_T_hand.size())
    steps.push_back(rollout.world_T_hand.size() - 1);
  constexpr int kScale = 4, kLabel = 18, kGap = 6;
  const insert3d::DepthCamera& camera = rig.front();  // every camera of a rig has one size
  const int image_w = camera.width * kScale, image_h = camera.height * kScale;
  const int cameras = static_cast<int>(rig.size());
  const int panel_h = cameras * image_h + (cameras - 1) * kGap;
  const int panel_w = normals ? 2 * image_w + kGap : image_w;
  const int cols = std::min<int>(columns, static_cast<int>(steps.size()));
  const int rows = (static_cast<int>(steps.size()) + cols - 1) / cols;
  cv::Mat canvas(rows * (panel_h + kLabel + kGap) + kGap, cols * (panel_w + kGap) + kGap, CV_8UC3,
                 cv::Scalar(255, 255, 255));
  std::vector<sim::Label> labels;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const int x = kGap + static_cast<int>(i % static_cast<std::size_t>(cols)) * (panel_w + kGap);
    const int y =
        kGap + static_cast<int>(i / static_cast<std::size_t>(cols)) * (panel_h + kLabel + kGap);
    for (int k = 0; k < cameras; ++k) {
      const insert3d::DepthCamera& eye = rig[static_cast<std::size_t>(k)];
      const int top = y + kLabel + k * (image_h + kGap);
      const CameraImage image =
          insert3d::render_depth(geometry, eye, rollout.world_T_hand[steps[i]], scene.world_T_slot);
      depth_panel(image, eye.max_range, kScale).copyTo(canvas(cv::Rect(x, top, image_w, image_h)));
      if (normals) {
        normals_panel(image, eye, kScale)
            .copyTo(canvas(cv::Rect(x + image_w + kGap, top, image_w, image_h)));
      }
    }
    labels.push_back({"step " + std::to_string(steps[i]), static_cast<double>(x),
                      static_cast<double>(y + kLabel - 5), 11.0});
  }
  return sim::labelled(drawing::to_image(canvas), labels);
}

}  // namespace handcentric::experiments
