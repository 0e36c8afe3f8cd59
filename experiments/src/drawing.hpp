#pragma once
// Drawing helpers the experiment figures share (OpenCV imgproc): colours, text, dashed lines,
// and the finished canvas as an RGB sim::Image.
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

#include "handcentric/sim/draw.hpp"

namespace handcentric::experiments::drawing {

inline cv::Scalar rgb(int r, int g, int b) {
  return cv::Scalar(b, g, r);
}  // OpenCV stores BGR

inline void text(cv::Mat& canvas, const std::string& s, cv::Point at, double scale = 0.5,
                 const cv::Scalar& colour = rgb(20, 20, 20)) {
  cv::putText(canvas, s, at, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

inline void dashed(cv::Mat& canvas, cv::Point a, cv::Point b, const cv::Scalar& colour) {
  const double length = std::hypot(b.x - a.x, b.y - a.y);
  const int pieces = std::max(1, static_cast<int>(length / 8.0));
  for (int i = 0; i < pieces; i += 2) {
    const double s0 = static_cast<double>(i) / pieces;
    const double s1 = std::min(1.0, static_cast<double>(i + 1) / pieces);
    cv::line(canvas, a + (b - a) * s0, a + (b - a) * s1, colour, 2, cv::LINE_AA);
  }
}

/// A BGR canvas as the RGB image the PNG writer takes.
inline sim::Image to_image(const cv::Mat& canvas_bgr) {
  cv::Mat rgb_mat;
  cv::cvtColor(canvas_bgr, rgb_mat, cv::COLOR_BGR2RGB);
  sim::Image image;
  image.width = rgb_mat.cols;
  image.height = rgb_mat.rows;
  image.rgb.assign(rgb_mat.data, rgb_mat.data + rgb_mat.total() * 3);
  return image;
}

}  // namespace handcentric::experiments::drawing
