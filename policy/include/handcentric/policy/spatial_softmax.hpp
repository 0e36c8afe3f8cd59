#pragma once
// SpatialSoftmax: the image encoder's feature maps turned into one image-plane point per channel,
// the soft-argmax of Levine, Finn, Darrell and Abbeel ("End-to-End Training of Deep Visuomotor
// Policies", 2016), as robomimic's and Diffusion Policy's visual encoders end. For channel c
// of a map z (height x width),
//
//   p_c(y, x) = exp(z(y, x, c)) / sum_{y', x'} exp(z(y', x', c))
//   feature 2c = sum p_c(y, x) u(x),  feature 2c + 1 = sum p_c(y, x) v(y)
//
// with u(x) = (2x + 1) / width - 1 and v(y) = (2y + 1) / height - 1 the pixel centres in
// [-1, 1]: the expected position of what the channel responds to. An expectation moves
// continuously as the map does, so it can place an edge between pixel centres, where the
// flattened map (ConvEncoder's features) only says which pixels changed.
// Backward (the softmax's Jacobian): dz(y, x, c) = p_c(y, x) (g_2c (u(x) - f_2c) +
// g_2c+1 (v(y) - f_2c+1)).
//
// Maps come as ConvEncoder writes them, (height, width, channels) per column with the channels
// fastest; the layer has no parameters. float32 loops (a softmax is a few thousand exps per
// image, next to the encoder's products); each channel's largest entry is subtracted before exp.
#include <Eigen/Core>

#include "handcentric/policy/conv2d.hpp"

namespace handcentric::policy {

class SpatialSoftmax {
 public:
  using Matrix = Eigen::MatrixXf;

  SpatialSoftmax() = default;
  /// Throws InvalidArgument for an empty map.
  explicit SpatialSoftmax(ImageShape map);

  const ImageShape& map_shape() const { return map_; }
  /// Two per channel: (x, y) of channel 0, then of channel 1, ...
  Eigen::Index output_size() const { return 2 * static_cast<Eigen::Index>(map_.channels); }

  /// maps (map size x B) to points (output_size x B); keeps the probabilities for backward().
  /// Throws InvalidArgument for another number of rows.
  const Matrix& forward(const Eigen::Ref<const Matrix>& maps);
  /// d loss / d maps of the last forward() from d loss / d points (output_size x B). Throws
  /// InvalidArgument for another shape (or no forward() before).
  const Matrix& backward(const Eigen::Ref<const Matrix>& d_points);

 private:
  ImageShape map_;
  Matrix probability_;  ///< p, as the maps are stored
  Matrix points_;
  Matrix d_maps_;
};

}  // namespace handcentric::policy
