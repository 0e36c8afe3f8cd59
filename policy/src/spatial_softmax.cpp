#include "handcentric/policy/spatial_softmax.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/policy/layer_watch.hpp"

namespace handcentric::policy {

SpatialSoftmax::SpatialSoftmax(ImageShape map) : map_(map) {
  if (map.channels < 1 || map.height < 1 || map.width < 1) {
    throw InvalidArgument("SpatialSoftmax: a map of " + std::to_string(map.channels) + " x " +
                          std::to_string(map.height) + " x " + std::to_string(map.width) +
                          " is empty: give at least one channel, row and column");
  }
}

const SpatialSoftmax::Matrix& SpatialSoftmax::forward(const Eigen::Ref<const Matrix>& maps) {
  if (maps.rows() != map_.size() || map_.channels < 1) {
    throw InvalidArgument("SpatialSoftmax input has " + std::to_string(maps.rows()) +
                          " rows, expected " + std::to_string(map_.size()) + " (" +
                          std::to_string(map_.height) + " x " + std::to_string(map_.width) + " x " +
                          std::to_string(map_.channels) + " per column)");
  }
  const int channels = map_.channels, pixels = map_.height * map_.width;
  probability_.resize(maps.rows(), maps.cols());
  points_.resize(output_size(), maps.cols());
  std::vector<float> largest(static_cast<std::size_t>(channels));
  std::vector<double> total(static_cast<std::size_t>(channels)), x_sum(total), y_sum(total);
  for (Eigen::Index b = 0; b < maps.cols(); ++b) {
    const float* z = maps.col(b).data();
    float* p = probability_.col(b).data();
    std::fill(largest.begin(), largest.end(), -INFINITY);
    for (int i = 0; i < pixels; ++i) {
      for (int c = 0; c < channels; ++c) largest[c] = std::max(largest[c], z[i * channels + c]);
    }
    std::fill(total.begin(), total.end(), 0.0);
    std::fill(x_sum.begin(), x_sum.end(), 0.0);
    std::fill(y_sum.begin(), y_sum.end(), 0.0);
    for (int y = 0; y < map_.height; ++y) {
      const double v = (2.0 * y + 1.0) / map_.height - 1.0;
      for (int x = 0; x < map_.width; ++x) {
        const double u = (2.0 * x + 1.0) / map_.width - 1.0;
        const int i = (y * map_.width + x) * channels;
        for (int c = 0; c < channels; ++c) {
          const float e = std::exp(z[i + c] - largest[c]);
          p[i + c] = e;
          total[c] += e;
          x_sum[c] += e * u;
          y_sum[c] += e * v;
        }
      }
    }
    for (int c = 0; c < channels; ++c) {
      points_(2 * c, b) = static_cast<float>(x_sum[c] / total[c]);
      points_(2 * c + 1, b) = static_cast<float>(y_sum[c] / total[c]);
      total[c] = 1.0 / total[c];
    }
    for (int i = 0; i < pixels; ++i) {
      for (int c = 0; c < channels; ++c)
        p[i * channels + c] = static_cast<float>(p[i * channels + c] * total[c]);
    }
  }
  watch_layer("encoder.keypoints", 0, points_);  // layer_watch.hpp
  return points_;
}

const SpatialSoftmax::Matrix& SpatialSoftmax::backward(const Eigen::Ref<const Matrix>& d_points) {
  if (d_points.rows() != output_size() || d_points.cols() != probability_.cols() ||
      probability_.size() == 0) {
    throw InvalidArgument("SpatialSoftmax::backward: d_points is " +
                          std::to_string(d_points.rows()) + "x" + std::to_string(d_points.cols()) +
                          ", expected " + std::to_string(output_size()) + "x" +
                          std::to_string(probability_.cols()) + " (call forward() first)");
  }
  const int channels = map_.channels;
  d_maps_.resize(probability_.rows(), probability_.cols());
  for (Eigen::Index b = 0; b < probability_.cols(); ++b) {
    const float* p = probability_.col(b).data();
    float* dz = d_maps_.col(b).data();
    for (int y = 0; y < map_.height; ++y) {
      const float v = static_cast<float>((2.0 * y + 1.0) / map_.height - 1.0);
      for (int x = 0; x < map_.width; ++x) {
        const float u = static_cast<float>((2.0 * x + 1.0) / map_.width - 1.0);
        const int i = (y * map_.width + x) * channels;
        for (int c = 0; c < channels; ++c) {
          dz[i + c] = p[i + c] * (d_points(2 * c, b) * (u - points_(2 * c, b)) +
                                  d_points(2 * c + 1, b) * (v - points_(2 * c + 1, b)));
        }
      }
    }
  }
  return d_maps_;
}

}  // namespace handcentric::policy
