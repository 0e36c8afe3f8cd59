// The products of one training step of the anchor network (57 -> 256 -> 256 -> 256 -> 24, batch
// 256) and of the image encoders, one at a time, on the kernel set this CPU runs (or
// HANDCENTRIC_KERNELS): where a step's time goes, per product. items/s x 1e-9 = GFLOP/s. It times
// the private kernel interface (kernel_set.hpp), which is why it lives here and not in bench/,
// whose benchmarks use the public API only. Built as build/bench/bench_kernels with the other
// benchmarks.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "handcentric/policy/kernels.hpp"
#include "kernels/kernel_set.hpp"

using handcentric::policy::kernels::Epilogue;
using handcentric::policy::kernels::Gemm;
using handcentric::policy::kernels::Op;

namespace {

constexpr int kBatch = 256;

// C (m x n) = op(A) op(B) (+ bias, for op(B) = B, the forward products) with the epilogue, and
// with `row_sums` the sums of A's rows too (Gemm::a_row_sums, a weight gradient's bias gradient).
void product(benchmark::State& state, Op op_a, Op op_b, int m, int n, int k, Epilogue epilogue,
             bool row_sums = false) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  const auto random = [&](std::size_t size) {
    std::vector<float> v(size);
    for (float& x : v) x = uniform(rng);
    return v;
  };
  const int lda = op_a == Op::none ? m : k, ldb = op_b == Op::none ? k : n;
  const std::vector<float> a = random(static_cast<std::size_t>(lda) * (op_a == Op::none ? k : m));
  const std::vector<float> b = random(static_cast<std::size_t>(ldb) * (op_b == Op::none ? n : k));
  const std::vector<float> bias = random(m), activation = random(static_cast<std::size_t>(m) * n);
  std::vector<float> c(static_cast<std::size_t>(m) * n),
      sigmoid = random(static_cast<std::size_t>(m) * n);
  for (float& s : sigmoid) s = 0.5f + 0.5f * s;
  Gemm gemm{op_a,     op_b, m,        n,   k,
            a.data(), lda,  b.data(), ldb, op_b == Op::none ? bias.data() : nullptr,
            c.data(), m};
  gemm.epilogue = epilogue;
  gemm.sigmoid = sigmoid.data();
  gemm.lds = m;
  gemm.activation = activation.data();
  std::vector<float> sums(static_cast<std::size_t>(m));
  if (row_sums) gemm.a_row_sums = sums.data();
  const auto& kernels = handcentric::policy::kernels::active();
  for (auto _ : state) {
    kernels.gemm(gemm);
    benchmark::DoNotOptimize(c.data());
  }
  state.SetItemsProcessed(state.iterations() * 2L * m * n * k);  // flops
}

// Forward: Z = W X + b (then SiLU on hidden layers, keeping sigmoid(Z)).
BENCHMARK_CAPTURE(product, forward_first_layer_silu, Op::none, Op::none, 256, kBatch, 57,
                  Epilogue::silu);
BENCHMARK_CAPTURE(product, forward_hidden_layer_silu, Op::none, Op::none, 256, kBatch, 256,
                  Epilogue::silu);
BENCHMARK_CAPTURE(product, forward_hidden_layer_no_epilogue, Op::none, Op::none, 256, kBatch, 256,
                  Epilogue::none);
BENCHMARK_CAPTURE(product, forward_output_layer, Op::none, Op::none, 24, kBatch, 256,
                  Epilogue::none);
// Backward: dW = delta A^T, and delta_below = (W^T delta) SiLU'.
BENCHMARK_CAPTURE(product, dw_output_layer, Op::none, Op::transpose, 24, 256, kBatch,
                  Epilogue::none);
BENCHMARK_CAPTURE(product, dx_output_layer_silu_derivative, Op::transpose, Op::none, 256, kBatch,
                  24, Epilogue::silu_derivative);
BENCHMARK_CAPTURE(product, dw_hidden_layer, Op::none, Op::transpose, 256, 256, kBatch,
                  Epilogue::none);
BENCHMARK_CAPTURE(product, dx_hidden_layer_silu_derivative, Op::transpose, Op::none, 256, kBatch,
                  256, Epilogue::silu_derivative);
BENCHMARK_CAPTURE(product, dw_first_layer, Op::none, Op::transpose, 256, 57, kBatch,
                  Epilogue::none);

// The image encoder's products (bench/bench_conv.cpp: 4 x 48 x 64 -> 16, 32, 32 filters of 3 x 3,
// stride 2), at the sizes ConvEncoder runs them at batch 256, on stored patch matrices: forward
// and W^T delta one chunk of samples at a time (4, 4 and 9 samples: patches of about 512 KB), the
// weight gradients over the whole batch; the weight gradients also add up delta's rows (the bias
// gradients). The encoder reads the patches of its forward products and weight gradients in
// place (offset_gemm: the same tiles, broadcasts from the padded map instead of the matrix).
constexpr int kPixels1 = 24 * 32, kPixels2 = 12 * 16, kPixels3 = 6 * 8;
constexpr int kColumns1 = kBatch * kPixels1, kColumns2 = kBatch * kPixels2,
              kColumns3 = kBatch * kPixels3;  // a weight gradient's k
BENCHMARK_CAPTURE(product, conv1_forward_silu, Op::none, Op::transpose, 16, 4 * kPixels1, 36,
                  Epilogue::silu);
BENCHMARK_CAPTURE(product, conv2_forward_silu, Op::none, Op::none, 32, 4 * kPixels2, 144,
                  Epilogue::silu);
BENCHMARK_CAPTURE(product, conv3_forward_silu, Op::none, Op::none, 32, 9 * kPixels3, 288,
                  Epilogue::silu);
BENCHMARK_CAPTURE(product, conv1_dw, Op::none, Op::none, 16, 36, kColumns1, Epilogue::none, true);
BENCHMARK_CAPTURE(product, conv2_dw, Op::none, Op::transpose, 32, 144, kColumns2, Epilogue::none,
                  true);
BENCHMARK_CAPTURE(product, conv3_dw, Op::none, Op::transpose, 32, 288, kColumns3, Epilogue::none,
                  true);
BENCHMARK_CAPTURE(product, conv2_d_patches, Op::transpose, Op::none, 144, 4 * kPixels2, 32,
                  Epilogue::none);
BENCHMARK_CAPTURE(product, conv3_d_patches, Op::transpose, Op::none, 288, 9 * kPixels3, 32,
                  Epilogue::none);

// The image policies' default first layer (6 x 48 x 64 -> 8 filters of 3 x 3, stride 2: 24 x 32
// output pixels, K = 54) as ConvEncoder runs it, from the padded maps stored by column phase.
// Forward, on one chunk of 3 samples: the offset product (8 filters in the lanes, half an AVX-512
// vector) against pixel_conv (the pixels in the lanes), both with the SiLU epilogue and the same
// bits. The weight gradient dW = delta P^T and db, on 64 and 256 samples (one product over the
// batch's copy, which backward reads whole: 5 and 20 MB, the latter from memory rather than L3):
// the offset product with the row sums of delta against pixel_conv_weights.
enum class FirstLayer {
  forward_filters_in_lanes,
  forward_pixels_in_lanes,
  weights_filters_in_lanes,
  weights_pixels_in_lanes
};
void first_layer(benchmark::State& state, FirstLayer mode) {
  const bool forward =
      mode == FirstLayer::forward_filters_in_lanes || mode == FirstLayer::forward_pixels_in_lanes;
  constexpr int kChannels = 6, kHeight = 48, kWidth = 64, kFilters = 8;
  constexpr int kOutHeight = 24, kOutWidth = 32, kK = 9 * kChannels;
  const int samples = forward ? 3 : static_cast<int>(state.range(0));
  constexpr long kPhase = (kWidth + 2) / 2, kRow = 2 * kPhase, kPlane = kRow * (kHeight + 2),
                 kSample = kPlane * kChannels;
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
  std::vector<float> maps(static_cast<std::size_t>(kSample) * samples);
  for (float& x : maps) x = uniform(rng);
  std::vector<float> weights(static_cast<std::size_t>(kFilters) * kK), bias(kFilters);
  for (float& w : weights) w = 0.1f * uniform(rng);
  for (float& b : bias) b = uniform(rng);
  std::vector<long> patches, pixels;
  for (int ky = 0; ky < 3; ++ky)
    for (int kx = 0; kx < 3; ++kx)
      for (int c = 0; c < kChannels; ++c)
        patches.push_back(c * kPlane + ky * kRow + kx % 2 * kPhase + kx / 2);
  for (int b = 0; b < samples; ++b)
    for (int oy = 0; oy < kOutHeight; ++oy)
      for (int ox = 0; ox < kOutWidth; ++ox) pixels.push_back(b * kSample + 2L * oy * kRow + ox);
  const int n = static_cast<int>(pixels.size());
  std::vector<float> c(static_cast<std::size_t>(kFilters) * n), sigmoid(c.size());
  for (float& x : c) x = uniform(rng);  // delta, for the weight gradient
  const auto& kernels = handcentric::policy::kernels::active();
  Gemm gemm{Op::none, Op::none,    kFilters, n,           kK,       weights.data(),
            kFilters, maps.data(), kK,       bias.data(), c.data(), kFilters};
  gemm.epilogue = Epilogue::silu;
  gemm.sigmoid = sigmoid.data();
  gemm.lds = kFilters;
  Gemm d_weights{Op::none, Op::none, kFilters,       kK,      n, c.data(), kFilters, maps.data(),
                 n,        nullptr,  weights.data(), kFilters};
  d_weights.a_row_sums = bias.data();
  for (auto _ : state) {
    switch (mode) {
      case FirstLayer::forward_filters_in_lanes:
        kernels.offset_gemm({gemm, patches.data(), pixels.data()});
        break;
      case FirstLayer::forward_pixels_in_lanes:
        kernels.pixel_conv({kK, samples * kOutHeight, kOutWidth, weights.data(), bias.data(),
                            maps.data(), patches.data(), pixels.data(), c.data(), sigmoid.data()});
        break;
      case FirstLayer::weights_filters_in_lanes:
        kernels.offset_gemm({d_weights, pixels.data(), patches.data()});
        break;
      case FirstLayer::weights_pixels_in_lanes:
        kernels.pixel_conv_weights({kK, samples * kOutHeight, kOutWidth, maps.data(),
                                    patches.data(), pixels.data(), c.data(), weights.data(),
                                    bias.data()});
        break;
    }
    benchmark::DoNotOptimize(c.data());
    benchmark::DoNotOptimize(weights.data());
  }
  state.SetItemsProcessed(state.iterations() * 2L * kFilters * n * kK);  // flops
}
BENCHMARK_CAPTURE(first_layer, default_conv1_forward_silu_filters_in_lanes,
                  FirstLayer::forward_filters_in_lanes);
BENCHMARK_CAPTURE(first_layer, default_conv1_forward_silu_pixels_in_lanes,
                  FirstLayer::forward_pixels_in_lanes);
BENCHMARK_CAPTURE(first_layer, default_conv1_weights_filters_in_lanes,
                  FirstLayer::weights_filters_in_lanes)
    ->Arg(64)
    ->Arg(256);
BENCHMARK_CAPTURE(first_layer, default_conv1_weights_pixels_in_lanes,
                  FirstLayer::weights_pixels_in_lanes)
    ->Arg(64)
    ->Arg(256);

}  // namespace

BENCHMARK_MAIN();
