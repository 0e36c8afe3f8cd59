#pragma once
// ConvEncoder: a small CNN that turns a minibatch of images into features for the MLP (the
// image policies of the paper's Sec. 4.3, where a ResNet-18 plays this part): a few Conv2d
// layers (conv2d.hpp), each followed by SiLU, usually with stride 2, then flattened.
//
// Images come one per column, (channels x height x width) each, width fastest, as PyTorch
// stores an image: an input is (channels height width x B). The hidden maps, and so the
// features, are stored (height, width, channels) with the channels fastest: the output is
// (out_height out_width out_channels x B), feature (y, x, c) of the last layer at
// (y out_width + x) out_channels + c.
// All parameters live in one flat vector (W_1, b_1, W_2, b_2, ...), as the MLP keeps them
// (conv2d.hpp gives a layer's layout), so that Adam, clipping and model files see one array.
// float32 on the run-time dispatched kernels (kernels.hpp): one product per layer with the bias
// and SiLU in its epilogue, reading its patches in place from the zero-padded input (an
// implicit im2col, kernels::OffsetGemm: no patch matrix is written); a first layer of 8 filters
// with the output pixels in the vector lanes instead (kernels::PixelConv, the same bits), its
// padded rows stored by column phase so that a row's windows start at consecutive floats;
// backward the two products of the gradients and col2im (row2im for the first layer's input).
// Below the first layer, the padded maps live only one L2-sized chunk of samples at a time:
// backward pads them again from the map below rather than keeping a whole batch's.
#include <Eigen/Core>
#include <random>
#include <span>
#include <vector>

#include "handcentric/policy/conv2d.hpp"

namespace handcentric::policy {

class ByteReader;
class ByteWriter;
namespace kernels {
struct KernelSet;
}

/// A layer's input with its zero padding, and where each patch entry of each output pixel is
/// in it: the patch matrix, read in place by the layer's products (kernels::OffsetGemm).
struct PaddedInput {
  Eigen::VectorXf maps;  ///< room for `samples` padded samples, whose borders are zero
  int samples = 0;
  std::vector<long> patch_offsets, pixel_offsets;
};

/// A batch of images read where they lie and normalized as the first layer reads them: a
/// training step's draw from its training set, without writing the normalized batch (tens of
/// MB at batch 256). Sample b is rows [first_row, first_row + input_size()) of column
/// columns[b] of `set`; value i of each is read as (x - mean[i]) inv_scale[i], rounded after the
/// subtraction and after the product (Normalizer::normalize's bits), or as it is when mean and
/// inv_scale are both empty.
struct PickedImages {
  Eigen::Ref<const Eigen::MatrixXf> set;
  Eigen::Index first_row = 0;
  std::span<const Eigen::Index> columns;
  std::span<const float> mean, inv_scale;
};

/// Samples per slice of an image policy's training step: forward and backward run through the
/// encoder and the MLP one slice at a time, and the parameter gradients are summed over the
/// slices (the whole batch's gradient, in another order of its sums). A slice's images and
/// activations (about 0.2 MB a sample for the default two-camera image) stay in cache from its
/// forward pass to its backward pass, where a batch of 256 (50 MB) would go through memory.
/// Chosen with bench_conv (docs/BENCHMARKS.md, "Image encoder": the slicing).
inline constexpr int kImageTrainSlice = 16;

/// One layer of a ConvEncoder (the input channels come from the layer before).
struct ConvLayerSpec {
  int out_channels = 16;
  int kernel = 3;
  int stride = 2;
  int padding = 1;
};

class ConvEncoder {
 public:
  using Matrix = Eigen::MatrixXf;
  using Vector = Eigen::VectorXf;

  ConvEncoder() = default;
  /// Throws InvalidArgument for no layer, or a layer Conv2d refuses (the message names the
  /// layer). Parameters start at zero: call initialize().
  ConvEncoder(ImageShape input, const std::vector<ConvLayerSpec>& layers);

  /// A copy is the network (architecture, parameters, gradient), not the activations of the
  /// last forward(): those are a training batch's (hundreds of MB at 64 x 48 and batch 256), and
  /// a sampler copies the encoder on every call. A copy's backward() needs its own forward().
  ConvEncoder(const ConvEncoder& other);
  ConvEncoder& operator=(const ConvEncoder& other);
  ConvEncoder(ConvEncoder&&) noexcept = default;
  ConvEncoder& operator=(ConvEncoder&&) noexcept = default;
  ~ConvEncoder() = default;

  /// PyTorch's default for Conv2d: W, b uniform in +-1/sqrt(K), from `rng` (same seed, same bits).
  void initialize(std::mt19937_64& rng);

  const ImageShape& input_shape() const { return layers_.front().input(); }
  /// The last layer's output; the features are its (height, width, channels).
  const ImageShape& output_shape() const { return layers_.back().output(); }
  Eigen::Index input_size() const { return input_shape().size(); }
  Eigen::Index output_size() const { return output_shape().size(); }
  const std::vector<Conv2d>& layers() const { return layers_; }
  /// Start of layer l's W in parameters(); its b follows W.
  Eigen::Index parameter_offset(int layer) const { return offsets_[layer]; }
  Eigen::Index parameter_count() const { return parameters_.size(); }

  Vector& parameters() { return parameters_; }
  const Vector& parameters() const { return parameters_; }
  /// d loss / d parameters, written by backward().
  const Vector& gradient() const { return gradient_; }

  /// Training forward pass (keeps what backward() needs): images (input_size x B) to
  /// features (output_size x B). Throws InvalidArgument for another number of rows.
  const Matrix& forward(const Eigen::Ref<const Matrix>& images);
  /// The same on picked, normalized images (PickedImages): the bits of forward() on those
  /// columns normalized by a Normalizer. Throws InvalidArgument for a first_row that leaves no
  /// room for an image, a column outside the set, or a mean or inv_scale of another length than
  /// input_size() (or one without the other).
  const Matrix& forward(const PickedImages& images);
  /// Backward pass from d loss / d features (output_size x B) of the last forward(): sets
  /// gradient() and returns d loss / d images (input_size x B).
  const Matrix& backward(const Eigen::Ref<const Matrix>& d_features);
  /// backward() without d loss / d images (one product and one col2im less).
  void backward_parameters(const Eigen::Ref<const Matrix>& d_features);

  /// The same on one given kernel set rather than the one in use (kernels::active()): the
  /// tests run every Highway target this CPU has, and sets with planted faults, through it.
  /// With input_gradient false, backward() is backward_parameters(): d loss / d images is not
  /// computed and the matrix returned holds an earlier one.
  const Matrix& forward(const Eigen::Ref<const Matrix>& images, const kernels::KernelSet& set);
  const Matrix& forward(const PickedImages& images, const kernels::KernelSet& set);
  const Matrix& backward(const Eigen::Ref<const Matrix>& d_features, const kernels::KernelSet& set,
                         bool input_gradient = true);

  /// The architecture (input shape, each layer's out_channels, kernel, stride, padding) and
  /// the parameters, little-endian, for a model file.
  void write(ByteWriter& out) const;
  /// Reads what write() wrote. Throws InvalidModelFile naming the source for a truncated
  /// record, an architecture Conv2d refuses or larger than the bytes that follow, or a
  /// parameter vector of the wrong length or with a non-finite entry.
  static ConvEncoder read(ByteReader& in);

 private:
  /// forward() on the images that start at images[b], normalized with mean and inv_scale
  /// (input_size() each) unless mean is null.
  const Matrix& forward(const std::vector<const float*>& images, const float* mean,
                        const float* inv_scale, const kernels::KernelSet& set);

  std::vector<Conv2d> layers_;
  std::vector<Eigen::Index> offsets_;
  Vector parameters_;
  Vector gradient_;
  int batch_ = 0;  ///< of the last forward()
  /// Each layer's input with its zero padding and the offsets of its patches in it
  /// (conv_encoder.cpp, reserve_padded and pad): the first layer's for the last forward()'s
  /// whole batch, kept for backward(); a hidden layer's for one chunk of samples at a time
  /// (forward and backward pad it). The buffers only grow, so their borders are zeroed once.
  std::vector<PaddedInput> padded_;
  std::vector<Matrix> sigmoid_;     ///< sigmoid(z) of each layer (out size x B)
  std::vector<Matrix> activation_;  ///< SiLU(z) of each layer; the last one is the features
  std::vector<Matrix> delta_;  ///< d loss / d (each layer's output), kept: no reallocation per step
  Vector d_patches_;
  Matrix d_images_;
};

}  // namespace handcentric::policy
