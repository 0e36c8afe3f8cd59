#pragma once
// The OpenCV raster of the 3D task's drawing (insert3d_drawing.cpp): colours, and the finished
// raster as an RGB sim::Image, on which sim/canvas.hpp writes the captions.
#include <opencv2/imgproc.hpp>
#include <string>

#include "handcentric/sim/draw.hpp"

namespace handcentric::experiments::drawing {

inline cv::Scalar rgb(int r, int g, int b) {
  return cv::Scalar(b, g, r);
}  // OpenCV stores BGR

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
