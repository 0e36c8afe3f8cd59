#include "handcentric/policy/conv_encoder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <string>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/policy/binary_io.hpp"
#include "handcentric/policy/errors.hpp"
#include "handcentric/policy/layer_watch.hpp"
#include "kernels/kernel_set.hpp"

namespace handcentric::policy {

using kernels::Op;

namespace {

std::vector<Conv2d> stack(ImageShape input, const std::vector<ConvLayerSpec>& specs) {
  if (specs.empty()) throw InvalidArgument("ConvEncoder needs at least one layer");
  std::vector<Conv2d> layers;
  for (std::size_t l = 0; l < specs.size(); ++l) {
    const ConvLayerSpec& spec = specs[l];
    try {
      layers.emplace_back(layers.empty() ? input : layers.back().output(), spec.out_channels,
                          spec.kernel, spec.stride, spec.padding);
    } catch (const InvalidArgument& error) {
      throw InvalidArgument("ConvEncoder layer " + std::to_string(l) + ": " + error.what());
    }
  }
  return layers;
}

Eigen::Index total_parameters(const std::vector<Conv2d>& layers) {
  Eigen::Index count = 0;
  for (const Conv2d& layer : layers) count += layer.parameter_count();
  return count;
}

// The patches of `layer` over `batch` images whose pixel (c, y, x) of sample b is at
// b sample_stride + c channel_stride + y row_stride + x column_stride.
kernels::ConvPatches patches_of(const Conv2d& layer, int batch, long sample_stride,
                                long channel_stride, long row_stride, long column_stride) {
  kernels::ConvPatches g;
  g.batch = batch;
  g.channels = layer.input().channels;
  g.height = layer.input().height;
  g.width = layer.input().width;
  g.kernel = layer.kernel();
  g.stride = layer.stride();
  g.padding = layer.padding();
  g.out_height = layer.output().height;
  g.out_width = layer.output().width;
  g.sample_stride = sample_stride;
  g.channel_stride = channel_stride;
  g.row_stride = row_stride;
  g.column_stride = column_stride;
  return g;
}

// The encoder's input, (channels, height, width) per sample, width fastest.
kernels::ConvPatches image_patches(const Conv2d& layer, int batch, long sample_stride) {
  const ImageShape& in = layer.input();
  return patches_of(layer, batch, sample_stride, static_cast<long>(in.height) * in.width, in.width,
                    1);
}

// A hidden map, (height, width, channels) per sample, channels fastest: as the layer before
// wrote it (out_channels x N, column-major).
kernels::ConvPatches map_patches(const Conv2d& layer, int batch) {
  const ImageShape& in = layer.input();
  return patches_of(layer, batch, in.size(), 1, static_cast<long>(in.width) * in.channels,
                    in.channels);
}

// Samples per chunk of the batch whose patch matrix (K x pixels each) fills about half of a
// 1 MB L2 (kernels/gemm.hpp assumes it): backward's col2im reads the patches' gradient from
// there (and the chunk's padded map, a ninth of it at kernel 3, is read in place). Below the
// first layer, a chunk's pixels are a multiple of the products' k block, so that the weight
// gradient summed chunk by chunk adds the same terms in the same order as one product over the
// batch.
int samples_per_chunk(const Conv2d& layer, bool first) {
  constexpr Eigen::Index kChunkFloats = Eigen::Index{1} << 17;  // 512 KB
  const int pixels = layer.output().height * layer.output().width;
  const Eigen::Index per_sample = static_cast<Eigen::Index>(layer.patch_size()) * pixels;
  const int fill = static_cast<int>(std::max<Eigen::Index>(1, kChunkFloats / per_sample));
  if (first) return fill;
  const int unit = kernels::kProductKBlock / std::gcd(pixels, kernels::kProductKBlock);
  return std::max(unit, fill / unit * unit);
}

// How a layer's input lies in its padded copy, in the input's own layout: (channels, height,
// width) for the encoder's input (channels_first), (height, width, channels) for a hidden map.
// Padded row Y of plane q starts at q plane + Y row. Channels first, there is a plane per channel
// and a padded row stores its columns by phase: column X at (X mod stride) phase + X / stride,
// so that the windows of consecutive output pixels of a row, stride columns apart, start at
// consecutive floats (what PixelConv reads in vectors). Channels last, one plane, and column X's
// channels at X channels.
struct PaddedLayout {
  bool channels_first;
  int planes, stride;
  long phase, row, plane, sample, channel_step, column_step;
  // Where padded column x (of channel 0) lies in its row.
  long column(long x) const {
    return channels_first ? x % stride * phase + x / stride : x * column_step;
  }
};

PaddedLayout padded_layout(const Conv2d& layer, bool channels_first) {
  const ImageShape& in = layer.input();
  const long padded_width = in.width + 2L * layer.padding();
  PaddedLayout l;
  l.channels_first = channels_first;
  l.planes = channels_first ? in.channels : 1;
  l.stride = layer.stride();
  l.phase = (padded_width + l.stride - 1) / l.stride;
  l.row = channels_first ? l.phase * l.stride : padded_width * in.channels;
  l.plane = l.row * (in.height + 2L * layer.padding());
  l.sample = l.plane * l.planes;
  l.channel_step = channels_first ? l.plane : 1;
  l.column_step = in.channels;
  return l;
}

// Makes room for `count` padded samples, if padded holds fewer: the maps all zeros (the copies
// below write only the interiors, so the borders stay zero from then on), and the offsets
// through which the layer's product reads its patches in place (kernels::OffsetGemm): entry
// (ky, kx, c) of output pixel (b, oy, ox) is maps[patch_offsets[(ky kernel + kx) channels + c] +
// pixel_offsets[(b out_height + oy) out_width + ox]], the patch matrix im2col would write. Its
// padded column ox stride + kx lies at column(kx) + column(ox stride) in either layout (channels
// first, in phase kx mod stride at ox + kx / stride; column(ox stride) = ox).
void reserve_padded(const Conv2d& layer, bool channels_first, int count, PaddedInput& padded) {
  if (count <= padded.samples) return;
  const PaddedLayout l = padded_layout(layer, channels_first);
  padded.maps = Eigen::VectorXf::Zero(l.sample * count);
  padded.samples = count;
  padded.patch_offsets.clear();
  for (int ky = 0; ky < layer.kernel(); ++ky) {
    for (int kx = 0; kx < layer.kernel(); ++kx) {
      for (int c = 0; c < layer.input().channels; ++c) {
        padded.patch_offsets.push_back(c * l.channel_step + ky * l.row + l.column(kx));
      }
    }
  }
  const ImageShape& out = layer.output();
  padded.pixel_offsets.resize(static_cast<std::size_t>(count) * out.height * out.width);
  std::size_t at = 0;
  for (int b = 0; b < count; ++b) {
    for (int oy = 0; oy < out.height; ++oy) {
      for (int ox = 0; ox < out.width; ++ox) {
        padded.pixel_offsets[at++] = b * l.sample + static_cast<long>(oy) * layer.stride() * l.row +
                                     l.column(static_cast<long>(ox) * layer.stride());
      }
    }
  }
}

// Copies `count` samples of a hidden layer's input (sample b at source + b source_stride,
// (height, width, channels)) into padded samples first, first + 1, ... (reserve_padded made
// room), interiors only.
void pad_maps(const Conv2d& layer, const float* source, long source_stride, int first, int count,
              PaddedInput& padded) {
  const PaddedLayout l = padded_layout(layer, false);
  const ImageShape& in = layer.input();
  const long run = static_cast<long>(in.width) * in.channels;
  for (int b = 0; b < count; ++b) {
    float* sample = padded.maps.data() + (first + b) * l.sample;
    for (int y = 0; y < in.height; ++y) {
      const float* from = source + b * source_stride + y * run;
      std::copy(from, from + run,
                sample + (y + layer.padding()) * l.row + l.column(layer.padding()));
    }
  }
}

// Copies images[first], ..., images[first + count - 1] (each (channels, height, width)) into the
// first layer's padded samples of the same numbers, interiors only, each value normalized on the
// way when `mean` is given: (x - mean) inv_scale, as kernels' deinterleave does it.
void pad_images(const Conv2d& layer, const std::vector<const float*>& images, const float* mean,
                const float* inv_scale, int first, int count, PaddedInput& padded,
                const kernels::KernelSet& set) {
  const PaddedLayout l = padded_layout(layer, true);
  const ImageShape& in = layer.input();
  const int pad = layer.padding();
  for (int b = first; b < first + count; ++b) {
    float* sample = padded.maps.data() + b * l.sample;
    for (int c = 0; c < in.channels; ++c) {
      for (int y = 0; y < in.height; ++y) {
        const long row = (static_cast<long>(c) * in.height + y) * in.width;
        const float* from = images[b] + row;
        const float* row_mean = mean == nullptr ? nullptr : mean + row;
        const float* row_inv_scale = mean == nullptr ? nullptr : inv_scale + row;
        float* to = sample + c * l.plane + (y + pad) * l.row;
        if (l.stride == 2) {
          // x even: padded column x + pad in phase pad mod 2 at (x + pad) / 2 = x / 2 + pad / 2;
          // x odd: in the other phase at (x - 1) / 2 + (pad + 1) / 2.
          set.deinterleave(in.width, from, row_mean, row_inv_scale, to + l.column(pad),
                           to + l.column(pad + 1));
          continue;
        }
        // Phase by phase: the columns x with (x + pad) mod stride = q go to phase q in order.
        for (int q = 0; q < l.stride; ++q) {
          const int x_first = ((q - pad) % l.stride + l.stride) % l.stride;
          float* phase = to + q * l.phase + (x_first + pad) / l.stride;
          const int columns = x_first < in.width ? (in.width - 1 - x_first) / l.stride + 1 : 0;
          for (int i = 0; i < columns; ++i) {
            const int x = x_first + i * l.stride;
            float v = from[x];
            if (row_mean != nullptr) {  // two roundings, as deinterleave's
              v -= row_mean[x];
              v *= row_inv_scale[x];
            }
            phase[i] = v;
          }
        }
      }
    }
  }
}

}  // namespace

ConvEncoder::ConvEncoder(const ConvEncoder& other)
    : layers_(other.layers_),
      offsets_(other.offsets_),
      parameters_(other.parameters_),
      gradient_(other.gradient_),
      padded_(other.layers_.size()),
      sigmoid_(other.layers_.size()),
      activation_(other.layers_.size()),
      delta_(other.layers_.size()) {}

ConvEncoder& ConvEncoder::operator=(const ConvEncoder& other) {
  if (this != &other) *this = ConvEncoder(other);
  return *this;
}

ConvEncoder::ConvEncoder(ImageShape input, const std::vector<ConvLayerSpec>& layers)
    : layers_(stack(input, layers)) {
  Eigen::Index count = 0;
  for (const Conv2d& layer : layers_) {
    offsets_.push_back(count);
    count += layer.parameter_count();
  }
  parameters_ = Vector::Zero(count);
  gradient_ = Vector::Zero(count);
  padded_.resize(layers_.size());
  sigmoid_.resize(layers_.size());
  activation_.resize(layers_.size());
  delta_.resize(layers_.size());
}

void ConvEncoder::initialize(std::mt19937_64& rng) {
  for (std::size_t l = 0; l < layers_.size(); ++l) {
    const double bound = 1.0 / std::sqrt(static_cast<double>(layers_[l].patch_size()));
    for (Eigen::Index i = 0; i < layers_[l].parameter_count(); ++i) {
      parameters_[offsets_[l] + i] = static_cast<float>(bound * (2.0 * uniform01(rng) - 1.0));
    }
  }
}

const ConvEncoder::Matrix& ConvEncoder::forward(const Eigen::Ref<const Matrix>& images) {
  return forward(images, kernels::active());
}

const ConvEncoder::Matrix& ConvEncoder::forward(const PickedImages& images) {
  return forward(images, kernels::active());
}

const ConvEncoder::Matrix& ConvEncoder::backward(const Eigen::Ref<const Matrix>& d_features) {
  return backward(d_features, kernels::active(), true);
}

void ConvEncoder::backward_parameters(const Eigen::Ref<const Matrix>& d_features) {
  backward(d_features, kernels::active(), false);
}

const ConvEncoder::Matrix& ConvEncoder::forward(const Eigen::Ref<const Matrix>& images,
                                                const kernels::KernelSet& set) {
  if (layers_.empty()) throw InvalidArgument("ConvEncoder::forward on an encoder without layers");
  if (images.rows() != input_size()) {
    throw InvalidArgument("ConvEncoder input has " + std::to_string(images.rows()) +
                          " rows, expected " + std::to_string(input_size()) + " (" +
                          std::to_string(input_shape().channels) + " x " +
                          std::to_string(input_shape().height) + " x " +
                          std::to_string(input_shape().width) + " per column)");
  }
  std::vector<const float*> samples(static_cast<std::size_t>(images.cols()));
  for (std::size_t b = 0; b < samples.size(); ++b)
    samples[b] = images.data() + static_cast<Eigen::Index>(b) * images.outerStride();
  return forward(samples, nullptr, nullptr, set);
}

const ConvEncoder::Matrix& ConvEncoder::forward(const PickedImages& images,
                                                const kernels::KernelSet& set) {
  if (layers_.empty()) throw InvalidArgument("ConvEncoder::forward on an encoder without layers");
  const Eigen::Index rows = images.set.rows();
  if (rows < input_size()) {
    throw InvalidArgument("ConvEncoder: a set of " + std::to_string(rows) +
                          " rows holds no image of " + std::to_string(input_size()) +
                          " rows: pass a set with the images in its columns");
  }
  if (images.first_row < 0 || images.first_row > rows - input_size()) {
    throw InvalidArgument("ConvEncoder: images from row " + std::to_string(images.first_row) +
                          " of a set of " + std::to_string(rows) + " rows, but an image has " +
                          std::to_string(input_size()) + " rows: pass a first_row in [0, " +
                          std::to_string(rows - input_size()) + "]");
  }
  const bool normalized = !images.mean.empty() || !images.inv_scale.empty();
  if (normalized && (static_cast<Eigen::Index>(images.mean.size()) != input_size() ||
                     static_cast<Eigen::Index>(images.inv_scale.size()) != input_size())) {
    throw InvalidArgument("ConvEncoder: a mean of " + std::to_string(images.mean.size()) +
                          " and an inv_scale of " + std::to_string(images.inv_scale.size()) +
                          " values for images of " + std::to_string(input_size()) +
                          ": give both with one value per image row, or neither");
  }
  std::vector<const float*> samples;
  samples.reserve(images.columns.size());
  for (const Eigen::Index j : images.columns) {
    if (j < 0 || j >= images.set.cols()) {
      throw InvalidArgument("ConvEncoder: column " + std::to_string(j) + " picked from a set of " +
                            std::to_string(images.set.cols()) + " columns");
    }
    samples.push_back(images.set.data() + j * images.set.outerStride() + images.first_row);
  }
  return forward(samples, normalized ? images.mean.data() : nullptr,
                 normalized ? images.inv_scale.data() : nullptr, set);
}

const ConvEncoder::Matrix& ConvEncoder::forward(const std::vector<const float*>& images,
                                                const float* mean, const float* inv_scale,
                                                const kernels::KernelSet& set) {
  const Eigen::Index batch = static_cast<Eigen::Index>(images.size());
  // The kernels count a layer's products in int: its patch matrix (K x pixels of the batch, read
  // in place) must have fewer than 2^31 entries.
  for (const Conv2d& layer : layers_) {
    const Eigen::Index columns = batch * layer.output().height * layer.output().width;
    if (columns * layer.patch_size() >= (Eigen::Index{1} << 31)) {
      throw InvalidArgument(
          "ConvEncoder batch of " + std::to_string(batch) +
          " images reads more than 2^31 patch entries in one layer: "
          "use a batch of at most " +
          std::to_string(((Eigen::Index{1} << 31) - 1) /
                         (columns / std::max<Eigen::Index>(batch, 1) * layer.patch_size())));
    }
  }
  batch_ = static_cast<int>(batch);
  for (std::size_t l = 0; l < layers_.size(); ++l) {
    const Conv2d& layer = layers_[l];
    const int pixels = layer.output().height * layer.output().width;
    const int k = layer.patch_size(), out = layer.out_channels();
    const float* weights = parameters_.data() + offsets_[l];
    activation_[l].resize(layer.output().size(), batch);
    sigmoid_[l].resize(layer.output().size(), batch);
    // a (out x N) = SiLU(W patches + b 1^T), sigmoid(z) kept for backward(), the patches read in
    // place from the padded input, one chunk of samples at a time, padded and multiplied while
    // it is in L2. The first layer keeps the whole batch's padded images for backward (which
    // does not see the images); a hidden layer's chunk is padded again by backward from the map
    // below.
    const int chunk = samples_per_chunk(layer, l == 0);
    PaddedInput& padded = padded_[l];
    reserve_padded(layer, l == 0, l == 0 ? batch_ : std::min(chunk, batch_), padded);
    for (int b0 = 0; b0 < batch_; b0 += chunk) {
      const int count = std::min(chunk, batch_ - b0);
      const Eigen::Index first = b0 * layer.output().size();
      // The first layer's chunk goes to its place in the whole batch's padded images; a hidden
      // layer's to the start of its chunk's room.
      const int at = l == 0 ? b0 : 0;
      if (l == 0) {
        pad_images(layer, images, mean, inv_scale, b0, count, padded, set);
      } else {
        pad_maps(layer, activation_[l - 1].data() + b0 * layer.input().size(), layer.input().size(),
                 at, count, padded);
      }
      if (l == 0 && out == kernels::kPixelConvFilters && count * pixels > kernels::kNarrowMax) {
        // Eight filters fill half of an AVX-512 vector: the pixels go in the lanes instead (the
        // same bits where offset_gemm would run its blocked nest).
        set.pixel_conv({k, count * layer.output().height, layer.output().width, weights,
                        weights + static_cast<Eigen::Index>(out) * k, padded.maps.data(),
                        padded.patch_offsets.data(),
                        padded.pixel_offsets.data() + static_cast<long>(at) * pixels,
                        activation_[l].data() + first, sigmoid_[l].data() + first});
        continue;
      }
      kernels::Gemm product{Op::none,
                            Op::none,
                            out,
                            count * pixels,
                            k,
                            weights,
                            out,
                            padded.maps.data(),
                            k,
                            weights + static_cast<Eigen::Index>(out) * k,
                            activation_[l].data() + first,
                            out};
      product.epilogue = kernels::Epilogue::silu;
      product.sigmoid = sigmoid_[l].data() + first;
      product.lds = out;
      set.offset_gemm({product, padded.patch_offsets.data(),
                       padded.pixel_offsets.data() + static_cast<long>(at) * pixels});
    }
    watch_layer("encoder.conv", static_cast<int>(l) + 1, activation_[l]);  // layer_watch.hpp
  }
  return activation_.back();
}

const ConvEncoder::Matrix& ConvEncoder::backward(const Eigen::Ref<const Matrix>& d_features,
                                                 const kernels::KernelSet& set,
                                                 bool input_gradient) {
  if (layers_.empty() || d_features.rows() != output_size() || d_features.cols() != batch_ ||
      batch_ == 0) {
    throw InvalidArgument("ConvEncoder::backward: d_features is " +
                          std::to_string(d_features.rows()) + "x" +
                          std::to_string(d_features.cols()) + ", expected " +
                          std::to_string(layers_.empty() ? 0 : output_size()) + "x" +
                          std::to_string(batch_) + " (call forward() first)");
  }
  delta_.back() = d_features;
  // Through the last layer's SiLU: delta *= SiLU'(z) = s + a (1 - s). The layers below get
  // theirs chunk by chunk, right after col2im completes their delta (below).
  set.silu_backward(delta_.back().size(), activation_.back().data(), sigmoid_.back().data(),
                    delta_.back().data());
  for (int l = static_cast<int>(layers_.size()) - 1; l >= 0; --l) {
    const Conv2d& layer = layers_[l];
    const int n = batch_ * layer.output().height * layer.output().width;
    const int k = layer.patch_size(), out = layer.out_channels();
    const Matrix& delta = delta_[l];
    float* d_weights = gradient_.data() + offsets_[l];
    float* d_bias = d_weights + static_cast<Eigen::Index>(out) * k;
    const int pixels = layer.output().height * layer.output().width;
    const int chunk = samples_per_chunk(layer, l == 0);
    const bool d_input = l > 0 || input_gradient;
    const Eigen::Index below = layer.input().size();
    float* target = nullptr;
    if (d_input) {
      Matrix& d_below = l == 0 ? d_images_ : delta_[l - 1];
      d_below.resize(below, batch_);
      target = d_below.data();
      d_patches_.resize(static_cast<Eigen::Index>(k) * pixels * std::min(chunk, batch_));
    }
    // dW (out x K) = delta patches^T and db = delta 1, the row sums of the product's A, added up
    // while it packs delta: for the first layer in one product, its patches^T (N x K) read in
    // place from the padded images forward() kept; below, chunk by chunk (in the loop).
    if (l == 0 && out == kernels::kPixelConvFilters && n > kernels::kNarrowMax) {
      // The pixels in the lanes, as forward() did (pixel_conv_weights: other bits than the
      // offset product on AVX-512).
      const PaddedInput& padded = padded_[0];
      set.pixel_conv_weights({k, batch_ * layer.output().height, layer.output().width,
                              padded.maps.data(), padded.patch_offsets.data(),
                              padded.pixel_offsets.data(), delta.data(), d_weights, d_bias});
      if (!d_input) break;
    } else if (l == 0) {
      const PaddedInput& padded = padded_[0];
      kernels::Gemm d_product{Op::none, Op::none,           out, k,       n,         delta.data(),
                              out,      padded.maps.data(), n,   nullptr, d_weights, out};
      d_product.a_row_sums = d_bias;
      set.offset_gemm({d_product, padded.pixel_offsets.data(), padded.patch_offsets.data()});
      if (!d_input) break;
    }
    // A chunk of samples at a time, so that the patches and their gradient are read from L2:
    // below the first layer, the chunk's patches again from the map below, dW += delta
    // patches^T and db += delta 1 (a chunk's pixels are a multiple of the products' k block, so
    // these are the sums of one product over the batch, bit for bit); then d patches (K x N) =
    // W^T delta, each entry back to the pixel it was read from. A chunk's pixels receive only its
    // own patches, so after its col2im they are complete: the chunk is zeroed just before (in
    // cache, not a pass over the whole map) and, below the first layer, multiplied by the layer
    // below's SiLU' just after.
    for (int b0 = 0; b0 < batch_; b0 += chunk) {
      const int count = std::min(chunk, batch_ - b0);
      const float* delta_chunk = delta.data() + b0 * layer.output().size();
      if (l > 0) {
        PaddedInput& padded = padded_[l];
        pad_maps(layer, activation_[l - 1].data() + b0 * below, below, 0, count, padded);
        kernels::Gemm d_product{
            Op::none, Op::none,           out, k,       count * pixels, delta_chunk,
            out,      padded.maps.data(), k,   nullptr, d_weights,      out};
        d_product.a_row_sums = d_bias;
        d_product.accumulate = b0 > 0;
        set.offset_gemm({d_product, padded.pixel_offsets.data(), padded.patch_offsets.data()});
      }
      const Eigen::Index first = b0 * below, size = count * below;
      if (l == 0) {
        // d patches^T (N x K) = delta^T W, back onto the image rows by row2im.
        set.gemm({Op::transpose, Op::none, count * pixels, k, out, delta_chunk, out,
                  parameters_.data() + offsets_[l], out, nullptr, d_patches_.data(),
                  count * pixels});
        std::fill(target + first, target + first + size, 0.0f);
        set.row2im(image_patches(layer, count, input_size()), d_patches_.data(), count * pixels,
                   target + first);
      } else {
        set.gemm({Op::transpose, Op::none, k, count * pixels, out, parameters_.data() + offsets_[l],
                  out, delta_chunk, out, nullptr, d_patches_.data(), k});
        std::fill(target + first, target + first + size, 0.0f);
        set.col2im(map_patches(layer, count), d_patches_.data(), target + first);
        set.silu_backward(size, activation_[l - 1].data() + first, sigmoid_[l - 1].data() + first,
                          target + first);
      }
    }
  }
  return d_images_;
}

void ConvEncoder::write(ByteWriter& out) const {
  out.u32(static_cast<std::uint32_t>(input_shape().channels));
  out.u32(static_cast<std::uint32_t>(input_shape().height));
  out.u32(static_cast<std::uint32_t>(input_shape().width));
  out.u32(static_cast<std::uint32_t>(layers_.size()));
  for (const Conv2d& layer : layers_) {
    out.u32(static_cast<std::uint32_t>(layer.out_channels()));
    out.u32(static_cast<std::uint32_t>(layer.kernel()));
    out.u32(static_cast<std::uint32_t>(layer.stride()));
    out.u32(static_cast<std::uint32_t>(layer.padding()));
  }
  out.floats(parameters_);
}

namespace {

// A u32 of the architecture as an int; values past INT32_MAX are refused here and small
// negative ones never occur, so Conv2d's checks see every value that could be meant.
int read_dimension(ByteReader& in, const std::string& what) {
  const std::uint32_t value = in.u32();
  if (value > 1u << 20) {
    in.fail("the image encoder's " + what + " is " + std::to_string(value) +
            ", more than the 2^20 a model file may give");
  }
  return static_cast<int>(value);
}

}  // namespace

ConvEncoder ConvEncoder::read(ByteReader& in) {
  constexpr std::uint32_t kMaxLayers = 64;
  ImageShape input;
  input.channels = read_dimension(in, "input channels");
  input.height = read_dimension(in, "input height");
  input.width = read_dimension(in, "input width");
  const std::uint32_t count = in.u32();
  if (count == 0 || count > kMaxLayers) {
    in.fail("the image encoder has " + std::to_string(count) + " layers, expected 1 to " +
            std::to_string(kMaxLayers));
  }
  std::vector<ConvLayerSpec> specs(count);
  for (std::uint32_t l = 0; l < count; ++l) {
    const std::string name = "layer " + std::to_string(l) + " ";
    specs[l].out_channels = read_dimension(in, name + "out_channels");
    specs[l].kernel = read_dimension(in, name + "kernel");
    specs[l].stride = read_dimension(in, name + "stride");
    specs[l].padding = read_dimension(in, name + "padding");
  }
  std::vector<Conv2d> layers;
  try {
    layers = stack(input, specs);
  } catch (const InvalidArgument& error) {
    in.fail(std::string("the image encoder's architecture is refused: ") + error.what());
  }
  // Before allocating: the parameters the architecture describes must be in the bytes that follow.
  const Eigen::Index parameters = total_parameters(layers);
  if (static_cast<std::uint64_t>(parameters) > in.remaining() / sizeof(float)) {
    in.fail("the image encoder's architecture has " + std::to_string(parameters) +
            " parameters but only " + std::to_string(in.remaining()) + " bytes follow");
  }
  ConvEncoder encoder(input, specs);
  encoder.parameters_ = in.floats(parameters);
  return encoder;
}

}  // namespace handcentric::policy
