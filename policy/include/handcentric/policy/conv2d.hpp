#pragma once
// Conv2d: the shape of one convolution layer of the image encoder (conv_encoder.hpp):
// out_channels filters of kernel x kernel x input channels, a stride and zero padding, then
// SiLU (the MLP's activation). The layer computes
//
//   a(o, oy, ox) = SiLU(b_o + sum_{ky, kx, c} W(o, (ky, kx, c)) x(c, oy s - p + ky, ox s - p + kx))
//
// as one product over the whole minibatch: W (out_channels x K) times the patch matrix
// (K x N, im2col), K = kernel^2 channels, N = batch out_height out_width.
// Parameters, as the MLP stores a layer: W column-major (out_channels x K), the patch index
// ordered (ky, kx, c) with c fastest, then b (out_channels).
#include <Eigen/Core>

namespace handcentric::policy {

/// An image of channels x height x width.
struct ImageShape {
  int channels = 0, height = 0, width = 0;
  Eigen::Index size() const {
    return static_cast<Eigen::Index>(channels) * height * static_cast<Eigen::Index>(width);
  }
  bool operator==(const ImageShape& other) const {
    return channels == other.channels && height == other.height && width == other.width;
  }
};

class Conv2d {
 public:
  /// Throws InvalidArgument naming the value and the fix for an input or out_channels < 1, a
  /// kernel < 1, a stride < 1, a padding < 0 or >= kernel, a kernel larger than the padded
  /// input, or a layer of more than 2^31 patch entries per image.
  Conv2d(ImageShape input, int out_channels, int kernel, int stride, int padding);

  const ImageShape& input() const { return input_; }
  /// out_channels x ((height + 2 padding - kernel) / stride + 1) x (the same for the width).
  const ImageShape& output() const { return output_; }
  int out_channels() const { return output_.channels; }
  int kernel() const { return kernel_; }
  int stride() const { return stride_; }
  int padding() const { return padding_; }
  /// K = kernel^2 input channels: a column of the patch matrix, a row of W.
  int patch_size() const { return kernel_ * kernel_ * input_.channels; }
  /// out_channels (K + 1): W, then b.
  Eigen::Index parameter_count() const {
    return static_cast<Eigen::Index>(out_channels()) * (patch_size() + 1);
  }

 private:
  ImageShape input_, output_;
  int kernel_ = 0, stride_ = 1, padding_ = 0;
};

}  // namespace handcentric::policy
