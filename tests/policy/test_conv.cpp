// The image encoder (ConvEncoder, conv2d.hpp) on the float32 kernels of every Highway target
// this build compiled and this CPU runs, against a naive double-precision convolution written
// here from the definition (direct sums, its own (c, y, x) storage): forward, the gradients of
// the weights, biases and input, with odd sizes, stride 1, 2 and 3, no padding, a kernel of 2 and
// images with a column stride. The reference's backward is checked by central differences of
// its forward, and the float encoder's by directional differences of its own. Each check is seen
// failing on kernel sets with a planted fault (a mutant product reading its patches in place,
// col2im, row2im, input-gradient product or SiLU', the first layer's pixel product or its rows'
// split by column phase), on every target. Then the model-file record of the encoder and the
// typed errors of bad shapes.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/policy/binary_io.hpp"
#include "handcentric/policy/conv2d.hpp"
#include "handcentric/policy/conv_encoder.hpp"
#include "handcentric/policy/errors.hpp"
#include "handcentric/policy/kernels.hpp"
#include "handcentric/policy/normalizer.hpp"
#include "kernels/kernel_set.hpp"
#include "throws.hpp"
#include "worst_error.hpp"  // tests/support

using namespace handcentric;
using namespace handcentric::policy;
using Catch::Matchers::Contains;

namespace {

std::vector<std::pair<std::string, const kernels::KernelSet*>> conv_targets() {
  std::vector<std::pair<std::string, const kernels::KernelSet*>> sets;
  for (std::int64_t target : kernels::available_targets()) {
    sets.emplace_back(kernels::target_name(target), &kernels::kernels_of_target(target));
  }
  return sets;
}

Eigen::MatrixXd random_matrix(Eigen::Index rows, Eigen::Index cols, std::mt19937_64& rng) {
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index i = 0; i < m.size(); ++i) m(i) = 2.0 * uniform01(rng) - 1.0;
  return m;
}

// The naive convolution stack in double. Maps are stored [b][c][y][x]; a layer's parameters are
// read from the encoder's flat vector by conv2d.hpp's layout (W(o, (ky, kx, c)) column-major,
// then b), the one thing shared with the code under test.
struct Reference {
  std::vector<Conv2d> layers;
  std::vector<Eigen::Index> offsets;
  Eigen::VectorXd parameters;
  int batch = 0;
  std::vector<std::vector<double>> input_of, z_of;  // per layer: its input map, its z

  explicit Reference(const ConvEncoder& encoder)
      : layers(encoder.layers()), parameters(encoder.parameters().cast<double>()) {
    for (std::size_t l = 0; l < layers.size(); ++l) offsets.push_back(encoder.parameter_offset(l));
  }
  static long at(const ImageShape& s, int b, int c, int y, int x) {
    return ((static_cast<long>(b) * s.channels + c) * s.height + y) * s.width + x;
  }
  double weight(int l, int o, int ky, int kx, int c) const {
    const Conv2d& layer = layers[l];
    const int k = (ky * layer.kernel() + kx) * layer.input().channels + c;
    return parameters[offsets[l] + o + static_cast<Eigen::Index>(k) * layer.out_channels()];
  }
  double bias(int l, int o) const {
    return parameters[offsets[l] +
                      static_cast<Eigen::Index>(layers[l].out_channels()) * layers[l].patch_size() +
                      o];
  }
  static double silu(double z) { return z / (1.0 + std::exp(-z)); }
  static double silu_derivative(double z) {
    const double s = 1.0 / (1.0 + std::exp(-z));
    return s * (1.0 + z * (1.0 - s));
  }

  // images (C H W x B), (c, y, x) per column; returns the features in the encoder's order,
  // (y, x, c) of the last layer per column.
  Eigen::MatrixXd forward(const Eigen::MatrixXd& images) {
    batch = static_cast<int>(images.cols());
    std::vector<double> map(images.data(), images.data() + images.size());
    input_of.assign(layers.size(), {});
    z_of.assign(layers.size(), {});
    for (std::size_t l = 0; l < layers.size(); ++l) {
      const Conv2d& layer = layers[l];
      const ImageShape &in = layer.input(), &out = layer.output();
      std::vector<double> z(static_cast<std::size_t>(batch * out.size()));
      for (int b = 0; b < batch; ++b)
        for (int o = 0; o < out.channels; ++o)
          for (int oy = 0; oy < out.height; ++oy)
            for (int ox = 0; ox < out.width; ++ox) {
              double sum = bias(static_cast<int>(l), o);
              for (int ky = 0; ky < layer.kernel(); ++ky)
                for (int kx = 0; kx < layer.kernel(); ++kx) {
                  const int iy = oy * layer.stride() - layer.padding() + ky;
                  const int ix = ox * layer.stride() - layer.padding() + kx;
                  if (iy < 0 || iy >= in.height || ix < 0 || ix >= in.width) continue;
                  for (int c = 0; c < in.channels; ++c)
                    sum += weight(static_cast<int>(l), o, ky, kx, c) * map[at(in, b, c, iy, ix)];
                }
              z[at(out, b, o, oy, ox)] = sum;
            }
      input_of[l] = std::move(map);
      map.resize(z.size());
      for (std::size_t i = 0; i < z.size(); ++i) map[i] = silu(z[i]);
      z_of[l] = std::move(z);
    }
    const ImageShape& out = layers.back().output();
    Eigen::MatrixXd features(out.size(), batch);
    for (int b = 0; b < batch; ++b)
      for (int c = 0; c < out.channels; ++c)
        for (int y = 0; y < out.height; ++y)
          for (int x = 0; x < out.width; ++x)
            features((static_cast<long>(y) * out.width + x) * out.channels + c, b) =
                map[at(out, b, c, y, x)];
    return features;
  }

  // From d loss / d features (encoder order) of the last forward: the parameter gradient (the
  // encoder's layout) and d loss / d images (C H W x B). `fault` plants a wrong backward:
  // 1 reads the weights with ky and kx swapped.
  std::pair<Eigen::VectorXd, Eigen::MatrixXd> backward(const Eigen::MatrixXd& d_features,
                                                       int fault = 0) const {
    Eigen::VectorXd gradient = Eigen::VectorXd::Zero(parameters.size());
    const ImageShape& last = layers.back().output();
    std::vector<double> delta(static_cast<std::size_t>(batch * last.size()));
    for (int b = 0; b < batch; ++b)
      for (int c = 0; c < last.channels; ++c)
        for (int y = 0; y < last.height; ++y)
          for (int x = 0; x < last.width; ++x)
            delta[at(last, b, c, y, x)] =
                d_features((static_cast<long>(y) * last.width + x) * last.channels + c, b);
    for (int l = static_cast<int>(layers.size()) - 1; l >= 0; --l) {
      const Conv2d& layer = layers[l];
      const ImageShape &in = layer.input(), &out = layer.output();
      for (std::size_t i = 0; i < delta.size(); ++i) delta[i] *= silu_derivative(z_of[l][i]);
      std::vector<double> below(static_cast<std::size_t>(batch * in.size()), 0.0);
      const Eigen::Index w0 = offsets[l];
      const Eigen::Index b0 = w0 + static_cast<Eigen::Index>(out.channels) * layer.patch_size();
      for (int b = 0; b < batch; ++b)
        for (int o = 0; o < out.channels; ++o)
          for (int oy = 0; oy < out.height; ++oy)
            for (int ox = 0; ox < out.width; ++ox) {
              const double d = delta[at(out, b, o, oy, ox)];
              gradient[b0 + o] += d;
              for (int ky = 0; ky < layer.kernel(); ++ky)
                for (int kx = 0; kx < layer.kernel(); ++kx) {
                  const int iy = oy * layer.stride() - layer.padding() + ky;
                  const int ix = ox * layer.stride() - layer.padding() + kx;
                  if (iy < 0 || iy >= in.height || ix < 0 || ix >= in.width) continue;
                  for (int c = 0; c < in.channels; ++c) {
                    const int k = (ky * layer.kernel() + kx) * in.channels + c;
                    gradient[w0 + o + static_cast<Eigen::Index>(k) * out.channels] +=
                        d * input_of[l][at(in, b, c, iy, ix)];
                    below[at(in, b, c, iy, ix)] +=
                        d * (fault == 1 ? weight(l, o, kx, ky, c) : weight(l, o, ky, kx, c));
                  }
                }
            }
      delta = std::move(below);
    }
    const ImageShape& in = layers.front().input();
    return {gradient, Eigen::Map<const Eigen::MatrixXd>(delta.data(), in.size(), batch)};
  }
};

double relative_error(const Eigen::MatrixXd& x, const Eigen::MatrixXd& reference) {
  return (x - reference).cwiseAbs().maxCoeff<Eigen::PropagateNaN>() /
         (1.0 + reference.cwiseAbs().maxCoeff<Eigen::PropagateNaN>());
}

struct Case {
  std::string name;
  ImageShape input;
  std::vector<ConvLayerSpec> layers;
  int batch;
};

// Odd sizes and channel counts that fill no vector, stride 1, 2 and 3, no padding, kernels 1, 2,
// 3 and 5, a 1 x 1 output; the image policies' depth and RGB-D encoders.
const std::vector<Case> kCases = {
    {"odd sizes", {3, 13, 11}, {{5, 3, 1, 1}, {7, 2, 2, 0}, {6, 3, 2, 1}}, 3},
    {"kernel 1 and 5", {2, 9, 7}, {{17, 1, 1, 0}, {4, 5, 1, 2}, {3, 3, 2, 0}}, 2},
    {"one output pixel", {1, 5, 5}, {{9, 5, 1, 0}}, 4},
    {"depth 24 x 32", {1, 24, 32}, {{8, 3, 2, 1}, {16, 3, 2, 1}, {16, 3, 2, 1}}, 5},
    {"rgb-d 48 x 64", {4, 48, 64}, {{16, 3, 2, 1}, {32, 3, 2, 1}, {32, 3, 2, 1}}, 2},
    // Patches of more than half a megabyte per image: the encoder works one image at a time.
    {"chunks of one image", {4, 64, 64}, {{8, 3, 1, 1}, {8, 3, 2, 1}}, 3},
    // A first layer of stride 3 (the windows' offsets and row2im at a stride other than 1 and 2).
    {"stride 3", {2, 11, 10}, {{4, 3, 3, 1}, {5, 2, 1, 0}}, 2},
};

// The results of one encoder run: features, parameter gradient, image gradient.
struct Run {
  Eigen::MatrixXd features, d_images;
  Eigen::VectorXd gradient;
};

// Forward and backward on `set`, with the images in a wider matrix (a column stride > rows).
Run run_on(ConvEncoder& encoder, const kernels::KernelSet& set, const Eigen::MatrixXd& images,
           const Eigen::MatrixXd& d_features) {
  Eigen::MatrixXf wide = Eigen::MatrixXf::Constant(images.rows() + 5, images.cols(), 1e30f);
  wide.topRows(images.rows()) = images.cast<float>();
  const Eigen::Ref<const Eigen::MatrixXf> view = wide.topRows(images.rows());
  Run run;
  run.features = encoder.forward(view, set).cast<double>();
  run.d_images = encoder.backward(d_features.cast<float>(), set).cast<double>();
  run.gradient = encoder.gradient().cast<double>();
  return run;
}

struct Errors {
  double features, gradient, d_images;
  double worst() const { return test::worst_of(test::worst_of(features, gradient), d_images); }
};

Errors errors_of(const Run& run, const Eigen::MatrixXd& features, const Eigen::VectorXd& gradient,
                 const Eigen::MatrixXd& d_images) {
  return {relative_error(run.features, features), relative_error(run.gradient, gradient),
          relative_error(run.d_images, d_images)};
}

constexpr double kTolerance = 1e-5;  // float against double, as for the Mlp (test_kernels.cpp)

// Planted faults: a kernel set that is `base` but for one function. The wrappers reach the base
// through this pointer (function pointers carry no state); the tests run on one thread.
const kernels::KernelSet* g_base = nullptr;

void col2im_window_shifted(const kernels::ConvPatches& shape, const float* patches, float* image) {
  kernels::ConvPatches wrong = shape;
  wrong.padding -= 1;  // every window one pixel down and right of where forward read it
  g_base->col2im(wrong, patches, image);
}
void gemm_short_k(const kernels::Gemm& problem) {
  kernels::Gemm wrong = problem;
  if (wrong.k > 1) wrong.k -= 1;  // the k loop stops one term short
  g_base->gemm(wrong);
}
void gemm_untransposed_weights(const kernels::Gemm& problem) {
  kernels::Gemm wrong = problem;
  // The input-gradient product W^T delta read as W delta (the first layer's delta^T W as
  // delta W). It stays inside the storage of W (of delta) only when K (the pixels of a chunk)
  // >= out_channels, which every case's layers have.
  if (wrong.op_a == kernels::Op::transpose && wrong.op_b == kernels::Op::none &&
      wrong.m >= wrong.k) {
    wrong.op_a = kernels::Op::none;
  }
  g_base->gemm(wrong);
}
void offset_gemm_patches_shifted(const kernels::OffsetGemm& problem) {
  // Every window read one float early (one pixel, or one channel of a hidden map): B copied one
  // float later (the reads stay inside the copy).
  const kernels::Gemm& g = problem.product;
  const long extent =
      *std::max_element(problem.b_row_offsets, problem.b_row_offsets + std::max(g.k, 1)) +
      *std::max_element(problem.b_column_offsets, problem.b_column_offsets + std::max(g.n, 1)) + 1;
  std::vector<float> shifted(static_cast<std::size_t>(extent) + 1, 0.0f);
  std::copy(g.b, g.b + extent, shifted.begin() + 1);
  kernels::OffsetGemm wrong = problem;
  wrong.product.b = shifted.data();
  g_base->offset_gemm(wrong);
}
void offset_gemm_short_k(const kernels::OffsetGemm& problem) {
  kernels::OffsetGemm wrong = problem;
  if (wrong.product.k > 1) wrong.product.k -= 1;  // a patch entry (a pixel, for dW) left out
  g_base->offset_gemm(wrong);
}
void row2im_window_shifted(const kernels::ConvPatches& shape, const float* rows, long ld,
                           float* image) {
  kernels::ConvPatches wrong = shape;
  wrong.padding -= 1;
  g_base->row2im(wrong, rows, ld, image);
}
void silu_backward_left_out(std::ptrdiff_t, const float*, const float*, float*) {}
void pixel_conv_short_k(const kernels::PixelConv& problem) {
  kernels::PixelConv wrong = problem;
  if (wrong.k > 1) wrong.k -= 1;  // the first layer's last patch entry left out
  g_base->pixel_conv(wrong);
}
void pixel_conv_weights_row_short(const kernels::PixelConvGradient& problem) {
  kernels::PixelConvGradient wrong = problem;
  if (wrong.rows > 1) wrong.rows -= 1;  // the first layer's dW without the batch's last row
  g_base->pixel_conv_weights(wrong);
}
void deinterleave_swapped(std::ptrdiff_t n, const float* x, const float* mean,
                          const float* inv_scale, float* even, float* odd) {
  // Each column phase gets the other's floats (a row of the first layer's padded copy misread).
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const std::ptrdiff_t other = (i ^ 1) < n ? (i ^ 1) : i;
    float v = x[other];
    if (mean != nullptr) {
      v -= mean[other];
      v *= inv_scale[other];
    }
    (i % 2 == 0 ? even : odd)[i / 2] = v;
  }
}

struct Mutant {
  std::string name;
  kernels::KernelSet set;
  bool forward_wrong;  // whether the features are wrong too, or only the gradients
  // The cases whose encoder calls the mutated function (null: every case).
  bool (*applies)(const Case& c) = nullptr;
};

std::vector<Mutant> mutants_of(const kernels::KernelSet& base) {
  using Set = kernels::KernelSet;
  const auto mutant = [&](std::string name, bool forward_wrong, void (*plant)(Set&),
                          bool (*applies)(const Case&) = nullptr) {
    Mutant m{std::move(name), base, forward_wrong, applies};
    plant(m.set);
    return m;
  };
  return {
      mutant("col2im window shifted", false, [](Set& set) { set.col2im = col2im_window_shifted; }),
      mutant("patches read one float early", true,
             [](Set& set) { set.offset_gemm = offset_gemm_patches_shifted; }),
      mutant("a layer's product one k term short", true,
             [](Set& set) { set.offset_gemm = offset_gemm_short_k; }),
      mutant("row2im window shifted", false, [](Set& set) { set.row2im = row2im_window_shifted; }),
      mutant("input-gradient product one k term short", false,
             [](Set& set) { set.gemm = gemm_short_k; }),
      mutant("input gradient through W, not W^T", false,
             [](Set& set) { set.gemm = gemm_untransposed_weights; }),
      mutant(
          "the first layer's pixel product one k term short", true,
          [](Set& set) { set.pixel_conv = pixel_conv_short_k; },
          [](const Case& c) { return c.layers.front().out_channels == 8; }),
      mutant(
          "the first layer's weight gradient a row of pixels short", false,
          [](Set& set) { set.pixel_conv_weights = pixel_conv_weights_row_short; },
          [](const Case& c) { return c.layers.front().out_channels == 8; }),
      mutant(
          "the first layer's rows split into the wrong column phases", true,
          [](Set& set) { set.deinterleave = deinterleave_swapped; },
          [](const Case& c) { return c.layers.front().stride == 2; }),
      // Last: the gradient check below takes it.
      mutant("SiLU' left out", false,
             [](Set& set) { set.silu_backward = silu_backward_left_out; })};
}

ConvEncoder encoder_of(const Case& c, std::uint64_t seed) {
  ConvEncoder encoder(c.input, c.layers);
  std::mt19937_64 rng(seed);
  encoder.initialize(rng);
  return encoder;
}

// One case's encoder, random images and d loss / d features, and the reference's answers.
struct Expected {
  ConvEncoder encoder;
  Eigen::MatrixXd images, d_features, features, d_images;
  Eigen::VectorXd gradient;

  Expected(const Case& c, std::uint64_t seed, std::mt19937_64& rng, double image_scale = 1.0)
      : encoder(encoder_of(c, seed)) {
    images = image_scale * random_matrix(c.input.size(), c.batch, rng);
    d_features = random_matrix(encoder.output_size(), c.batch, rng);
    Reference reference(encoder);
    features = reference.forward(images);
    std::tie(gradient, d_images) = reference.backward(d_features);
  }
  Errors errors(const kernels::KernelSet& set) {
    return errors_of(run_on(encoder, set, images, d_features), features, gradient, d_images);
  }
};

}  // namespace

TEST_CASE("conv_encoder_on_every_target_matches_the_double_reference", "[unit]") {
  std::mt19937_64 rng(41);
  for (const Case& c : kCases) {
    // Inputs of a few units: z spans both sides of SiLU's bend.
    Expected expected(c, 42, rng, 2.0);
    for (const auto& [name, set] : conv_targets()) {
      INFO(c.name << ", target " << name);
      const Errors e = expected.errors(*set);
      CHECK(e.features < kTolerance);
      CHECK(e.gradient < kTolerance);
      CHECK(e.d_images < kTolerance);
    }
  }
}

TEST_CASE("mutant_conv_kernel_sets_are_caught_on_every_target", "[unit]") {
  std::mt19937_64 rng(43);
  for (const Case& c : kCases) {
    if (c.name == "one output pixel") continue;  // no stride or col2im overlap to get wrong
    Expected expected(c, 44, rng, 2.0);
    for (const auto& [name, set] : conv_targets()) {
      g_base = set;
      for (const Mutant& mutant : mutants_of(*set)) {
        if (mutant.applies != nullptr && !mutant.applies(c)) continue;
        INFO(c.name << ", target " << name << ", mutant: " << mutant.name);
        const Errors e = expected.errors(mutant.set);
        CHECK(e.worst() > 100 * kTolerance);
        if (mutant.forward_wrong) CHECK(e.features > 100 * kTolerance);
        if (!mutant.forward_wrong) CHECK(e.features < kTolerance);
      }
    }
    g_base = nullptr;
  }
}

TEST_CASE("conv_encoder_on_every_named_kernel_set_matches_the_reference", "[unit]") {
  // The public calls (kernels::active()) on each set the process can be switched to.
  const KernelIsa saved = kernel_isa();
  std::mt19937_64 rng(45);
  Expected expected(kCases[0], 46, rng);
  ConvEncoder& encoder = expected.encoder;
  const Eigen::MatrixXd &images = expected.images, &d_features = expected.d_features;
  const Eigen::MatrixXd &features = expected.features, &d_images = expected.d_images;
  const Eigen::VectorXd& gradient = expected.gradient;
  for (KernelIsa isa : {KernelIsa::generic, KernelIsa::avx2, KernelIsa::avx512}) {
    if (!kernel_isa_supported(isa)) continue;
    INFO("kernel set " << to_string(isa));
    set_kernel_isa(isa);
    const Eigen::MatrixXf out = encoder.forward(images.cast<float>());
    CHECK(relative_error(out.cast<double>(), features) < kTolerance);
    encoder.backward_parameters(d_features.cast<float>());
    CHECK(relative_error(encoder.gradient().cast<double>(), gradient) < kTolerance);
    const Eigen::MatrixXf din = encoder.backward(d_features.cast<float>());
    CHECK(relative_error(din.cast<double>(), d_images) < kTolerance);
  }
  set_kernel_isa(saved);
}

TEST_CASE("the_reference_backward_matches_central_differences", "[unit]") {
  // L = <d_features, features>: its exact gradient is the reference's backward(d_features).
  std::mt19937_64 rng(47);
  const Case& c = kCases[0];
  ConvEncoder encoder = encoder_of(c, 48);
  const Eigen::MatrixXd images = random_matrix(c.input.size(), c.batch, rng);
  const Eigen::MatrixXd d_features = random_matrix(encoder.output_size(), c.batch, rng);
  Reference reference(encoder);
  reference.forward(images);
  const auto [gradient, d_images] = reference.backward(d_features);
  const auto [wrong_gradient, wrong_d_images] = reference.backward(d_features, /*fault=*/1);
  const double h = 1e-6;
  const auto loss = [&](Reference& r, const Eigen::MatrixXd& x) {
    return (r.forward(x).array() * d_features.array()).sum();
  };
  double worst_p = 0, worst_x = 0, wrong_x = 0;
  for (Eigen::Index i = 0; i < gradient.size(); i += 7) {
    Reference r = reference;
    r.parameters[i] += h;
    const double plus = loss(r, images);
    r.parameters[i] -= 2 * h;
    const double minus = loss(r, images);
    worst_p = test::worst_of(worst_p, std::abs((plus - minus) / (2 * h) - gradient[i]));
  }
  for (Eigen::Index i = 0; i < images.size(); i += 5) {
    Reference r = reference;
    Eigen::MatrixXd x = images;
    x(i) += h;
    const double plus = loss(r, x);
    x(i) -= 2 * h;
    const double minus = loss(r, x);
    const double numeric = (plus - minus) / (2 * h);
    worst_x = test::worst_of(worst_x, std::abs(numeric - d_images(i)));
    wrong_x = test::worst_of(wrong_x, std::abs(numeric - wrong_d_images(i)));
  }
  CHECK(worst_p < 1e-6);
  CHECK(worst_x < 1e-6);
  CHECK(wrong_x > 1e-3);  // planted fault: the input gradient through W with ky, kx swapped
}

TEST_CASE("the_float_encoder_gradient_matches_directional_differences", "[unit]") {
  // d/dh L(theta + h v) = <gradient, v> for a random direction v, L = <g, features>, by central
  // differences of the float encoder itself (h = 1e-2: float rounding of L stays far below).
  std::mt19937_64 rng(49);
  const Case& c = kCases[3];
  ConvEncoder encoder = encoder_of(c, 50);
  const Eigen::MatrixXf images = random_matrix(c.input.size(), c.batch, rng).cast<float>();
  const Eigen::MatrixXf g = random_matrix(encoder.output_size(), c.batch, rng).cast<float>();
  encoder.forward(images);
  const Eigen::MatrixXd d_images = encoder.backward(g).cast<double>();
  const Eigen::VectorXd gradient = encoder.gradient().cast<double>();
  const Eigen::VectorXf theta = encoder.parameters();
  const Eigen::VectorXf v = random_matrix(theta.size(), 1, rng).cast<float>();
  const Eigen::MatrixXf u = random_matrix(images.rows(), images.cols(), rng).cast<float>();
  const auto loss = [&](const Eigen::MatrixXf& x) {
    return (encoder.forward(x).cast<double>().array() * g.cast<double>().array()).sum();
  };
  const float h = 1e-2f;
  encoder.parameters() = theta + h * v;
  const double plus = loss(images);
  encoder.parameters() = theta - h * v;
  const double minus = loss(images);
  encoder.parameters() = theta;
  const double along_v = gradient.dot(v.cast<double>());
  CHECK(std::abs((plus - minus) / (2 * h) - along_v) < 1e-2 * (1 + std::abs(along_v)));
  const Eigen::MatrixXf image_plus = images + h * u, image_minus = images - h * u;
  const double numeric_u = (loss(image_plus) - loss(image_minus)) / (2 * h);
  const double along_u = (d_images.array() * u.cast<double>().array()).sum();
  CHECK(std::abs(numeric_u - along_u) < 1e-2 * (1 + std::abs(along_u)));
  // Planted fault: the same check against the gradient of the mutant without SiLU'.
  g_base = &kernels::active();
  const kernels::KernelSet no_derivative = mutants_of(kernels::active()).back().set;
  encoder.forward(images, no_derivative);
  encoder.backward(g, no_derivative);
  const double wrong = encoder.gradient().cast<double>().dot(v.cast<double>());
  g_base = nullptr;
  CHECK(std::abs((plus - minus) / (2 * h) - wrong) > 1e-2 * (1 + std::abs(wrong)));
}

TEST_CASE("conv_encoder_is_deterministic_for_a_seed", "[unit]") {
  const Case& c = kCases[4];
  ConvEncoder a = encoder_of(c, 7), b = encoder_of(c, 7), other = encoder_of(c, 8);
  CHECK(a.parameters() == b.parameters());
  CHECK(a.parameters() != other.parameters());
  std::mt19937_64 rng(9);
  const Eigen::MatrixXf images = random_matrix(c.input.size(), 3, rng).cast<float>();
  const Eigen::MatrixXf first = a.forward(images);
  const Eigen::MatrixXf d_first = a.backward(first);
  const Eigen::VectorXf g_first = a.gradient();
  CHECK(b.forward(images) == first);
  CHECK(b.backward(first) == d_first);
  CHECK(b.gradient() == g_first);
}

TEST_CASE("conv_shapes_are_refused_with_the_value_and_the_fix", "[unit]") {
  HC_CHECK_THROWS(Conv2d({0, 8, 8}, 4, 3, 1, 1), InvalidArgument,
                  Contains("input channels is 0") && Contains("at least one channel"));
  HC_CHECK_THROWS(Conv2d({1, 8, 8}, 0, 3, 1, 1), InvalidArgument, Contains("out_channels is 0"));
  HC_CHECK_THROWS(Conv2d({1, 8, 8}, 4, 0, 1, 0), InvalidArgument, Contains("kernel is 0"));
  HC_CHECK_THROWS(Conv2d({1, 8, 8}, 4, 3, 0, 1), InvalidArgument,
                  Contains("stride is 0") && Contains("use 1, or 2"));
  HC_CHECK_THROWS(Conv2d({1, 8, 8}, 4, 3, 1, -1), InvalidArgument, Contains("padding is -1"));
  HC_CHECK_THROWS(Conv2d({1, 8, 8}, 4, 3, 1, 3), InvalidArgument,
                  Contains("padding is 3 with a kernel of 3") && Contains("padding < kernel"));
  HC_CHECK_THROWS(
      Conv2d({1, 4, 8}, 4, 7, 1, 1), InvalidArgument,
      Contains("kernel is 7 but the padded input is 6 x 10") && Contains("smaller kernel"));
  const Conv2d layer({4, 48, 64}, 16, 3, 2, 1);
  CHECK(layer.output() == ImageShape{16, 24, 32});
  CHECK(layer.patch_size() == 36);
  CHECK(layer.parameter_count() == 16 * 37);
  HC_CHECK_THROWS(ConvEncoder({1, 8, 8}, {}), InvalidArgument, Contains("at least one layer"));
  // The third stride-2 layer of an 8 x 8 image sees a 2 x 2 map: a kernel of 5 does not fit.
  HC_CHECK_THROWS(ConvEncoder({1, 8, 8}, {{4, 3, 2, 1}, {4, 3, 2, 1}, {4, 5, 2, 1}}),
                  InvalidArgument, Contains("layer 2: Conv2d kernel is 5"));
  ConvEncoder encoder({1, 8, 8}, {{4, 3, 2, 1}});
  HC_CHECK_THROWS(encoder.forward(Eigen::MatrixXf::Zero(63, 2)), InvalidArgument,
                  Contains("63 rows, expected 64") && Contains("1 x 8 x 8"));
  HC_CHECK_THROWS(encoder.backward(Eigen::MatrixXf::Zero(64, 2)), InvalidArgument,
                  Contains("call forward() first"));
}

namespace {

std::string record_of(const ConvEncoder& encoder) {
  ByteWriter out;
  encoder.write(out);
  return out.bytes();
}

ConvEncoder read_record(const std::string& bytes) {
  ByteReader in(bytes, "encoder.bin");
  ConvEncoder encoder = ConvEncoder::read(in);
  if (!in.at_end()) in.fail("bytes after the encoder");
  return encoder;
}

// A record with the u32 at byte `offset` replaced.
std::string with_u32(std::string bytes, std::size_t offset, std::uint32_t value) {
  for (int i = 0; i < 4; ++i) bytes[offset + i] = static_cast<char>((value >> (8 * i)) & 0xff);
  return bytes;
}

}  // namespace

TEST_CASE("conv_encoder_record_round_trips_bit_for_bit", "[unit]") {
  const Case& c = kCases[0];
  const ConvEncoder encoder = encoder_of(c, 51);
  ConvEncoder read = read_record(record_of(encoder));
  CHECK(read.parameters() == encoder.parameters());
  CHECK(read.input_shape() == encoder.input_shape());
  REQUIRE(read.layers().size() == encoder.layers().size());
  for (std::size_t l = 0; l < read.layers().size(); ++l) {
    CHECK(read.layers()[l].output() == encoder.layers()[l].output());
    CHECK(read.layers()[l].kernel() == encoder.layers()[l].kernel());
    CHECK(read.layers()[l].stride() == encoder.layers()[l].stride());
    CHECK(read.layers()[l].padding() == encoder.layers()[l].padding());
  }
  std::mt19937_64 rng(52);
  const Eigen::MatrixXf images = random_matrix(c.input.size(), 2, rng).cast<float>();
  ConvEncoder copy = encoder;
  CHECK(read.forward(images) == copy.forward(images));
}

TEST_CASE("bad_conv_encoder_records_are_invalid_model_files", "[unit]") {
  const ConvEncoder encoder = encoder_of(kCases[0], 53);
  const std::string good = record_of(encoder);
  // Truncated anywhere: in the architecture, the length of the weights, or the weights.
  for (std::size_t size : {std::size_t{0}, std::size_t{2}, std::size_t{13}, std::size_t{40},
                           std::size_t{65}, good.size() - 1}) {
    INFO("truncated to " << size << " bytes");
    CHECK_THROWS_AS(read_record(good.substr(0, size)), InvalidModelFile);
  }
  // Layout: 3 u32 of the input, the layer count at 12, then 4 u32 per layer from 16.
  HC_CHECK_THROWS(read_record(with_u32(good, 12, 0)), InvalidModelFile,
                  Contains("encoder.bin") && Contains("0 layers, expected 1 to 64"));
  HC_CHECK_THROWS(read_record(with_u32(good, 16 + 4, 20)), InvalidModelFile,
                  Contains("layer 0: Conv2d kernel is 20"));
  HC_CHECK_THROWS(read_record(with_u32(good, 0, 0)), InvalidModelFile,
                  Contains("input channels is 0"));
  HC_CHECK_THROWS(read_record(with_u32(good, 4, 3000000000u)), InvalidModelFile,
                  Contains("input height is 3000000000"));
  // A wider layer than the weights stored: refused before anything of its size is allocated.
  HC_CHECK_THROWS(read_record(with_u32(good, 16, 1u << 20)), InvalidModelFile,
                  Contains("parameters but only"));
  // Another input shape (more channels) with the same weights: a wrong weight count.
  HC_CHECK_THROWS(read_record(with_u32(good, 16 + 16, 6)), InvalidModelFile,
                  Contains("encoder.bin"));
}

TEST_CASE("a_copy_of_an_encoder_is_its_weights_not_its_last_batch", "[unit]") {
  std::mt19937_64 rng(61);
  const Case& c = kCases[0];
  ConvEncoder trained = encoder_of(c, 62);
  const Eigen::MatrixXf images = random_matrix(c.input.size(), c.batch, rng).cast<float>();
  const Eigen::MatrixXf d_features =
      random_matrix(trained.output_size(), c.batch, rng).cast<float>();
  const Eigen::MatrixXf features = trained.forward(images);
  // The sampler's copy: the same network, without the batch that training kept for backward()
  // (a copy that carried it cost a copy of the training batch's patches per sampled chunk).
  ConvEncoder copy = trained;
  CHECK(copy.parameters() == trained.parameters());
  HC_CHECK_THROWS(copy.backward_parameters(d_features), InvalidArgument,
                  Catch::Contains("call forward() first"));
  CHECK(copy.forward(images) == features);
  copy.backward_parameters(d_features);
  trained.backward_parameters(d_features);
  CHECK(copy.gradient() == trained.gradient());
  // Assignment likewise.
  ConvEncoder assigned = encoder_of(kCases[1], 63);
  assigned = trained;
  HC_CHECK_THROWS(assigned.backward_parameters(d_features), InvalidArgument,
                  Catch::Contains("call forward() first"));
  CHECK(assigned.forward(images) == features);
}

// Training reads its batch from the training set: forward(PickedImages) normalizes each value
// as the first layer pads it. It must give the bits of the encoder run on those columns
// normalized by the Normalizer, forward and backward, on every target, at strides 1, 2 and 3
// (deinterleave's vectors and the scalar phases). Planted fault: the images read one row early.
TEST_CASE("picked_images_normalized_as_read_give_the_bits_of_a_normalized_copy", "[unit]") {
  std::mt19937_64 rng(71);
  constexpr int kProprioRows = 3;
  for (const Case& c : kCases) {
    const Eigen::Index rows = kProprioRows + c.input.size();
    const Eigen::MatrixXf set_columns = random_matrix(rows, c.batch + 3, rng).cast<float>();
    Eigen::VectorXd mean(rows), scale(rows);
    for (Eigen::Index i = 0; i < rows; ++i) {
      mean[i] = uniform01(rng) - 0.5;
      scale[i] = 0.2 + uniform01(rng);
    }
    const Normalizer normalizer(mean, scale);
    // Columns out of order, one of them twice.
    std::vector<Eigen::Index> picked;
    for (int b = 0; b < c.batch; ++b) picked.push_back((2 * b + 1) % (c.batch + 3));
    picked.back() = picked.front();
    Eigen::MatrixXf copy;
    normalizer.normalize(set_columns, picked, copy);
    const Eigen::MatrixXf images = copy.bottomRows(c.input.size());
    const auto n = static_cast<std::size_t>(c.input.size());
    const std::span<const float> image_mean(normalizer.mean_float().data() + kProprioRows, n);
    const std::span<const float> image_inv_scale(normalizer.inv_scale_float().data() + kProprioRows,
                                                 n);
    const Eigen::MatrixXf d_features =
        random_matrix(encoder_of(c, 72).output_size(), c.batch, rng).cast<float>();
    for (const auto& [name, set] : conv_targets()) {
      INFO(c.name << ", target " << name);
      ConvEncoder encoder = encoder_of(c, 72);
      const Eigen::MatrixXf features = encoder.forward(images, *set);
      const Eigen::MatrixXf d_images = encoder.backward(d_features, *set);
      const Eigen::VectorXf gradient = encoder.gradient();
      CHECK(encoder.forward(
                PickedImages{set_columns, kProprioRows, picked, image_mean, image_inv_scale},
                *set) == features);
      CHECK(encoder.backward(d_features, *set) == d_images);
      CHECK(encoder.gradient() == gradient);
      CHECK(encoder.forward(
                PickedImages{set_columns, kProprioRows - 1, picked, image_mean, image_inv_scale},
                *set) != features);
    }
  }
}

TEST_CASE("picked_images_outside_the_set_are_refused_with_the_value_and_the_fix", "[unit]") {
  const Case& c = kCases[0];
  ConvEncoder encoder = encoder_of(c, 73);
  const Eigen::Index n = c.input.size();
  const Eigen::MatrixXf set_columns = Eigen::MatrixXf::Zero(n + 2, 4);
  const std::vector<float> ones(static_cast<std::size_t>(n), 1.0f);
  const std::vector<Eigen::Index> good = {0, 3}, outside = {0, 4};
  CHECK(encoder.forward(PickedImages{set_columns, 2, good, ones, ones}).cols() == 2);
  HC_CHECK_THROWS(encoder.forward(PickedImages{set_columns, 3, good, ones, ones}), InvalidArgument,
                  Catch::Contains("from row 3") && Catch::Contains("[0, 2]"));
  HC_CHECK_THROWS(encoder.forward(PickedImages{set_columns.topRows(n - 1), 0, good, ones, ones}),
                  InvalidArgument, Catch::Contains("holds no image of " + std::to_string(n)));
  HC_CHECK_THROWS(encoder.forward(PickedImages{set_columns, 2, outside, ones, ones}),
                  InvalidArgument, Catch::Contains("column 4 picked from a set of 4 columns"));
  HC_CHECK_THROWS(encoder.forward(PickedImages{set_columns, 2, good, ones, {}}), InvalidArgument,
                  Catch::Contains("give both"));
  HC_CHECK_THROWS(
      encoder.forward(PickedImages{set_columns, 2, good, std::span<const float>(ones).first(3),
                                   std::span<const float>(ones).first(3)}),
      InvalidArgument, Catch::Contains("a mean of 3"));
}
