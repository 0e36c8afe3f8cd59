// Image-encoder speed: the training step of a small CNN feeding the flow MLP, the network of
// bench/vs_pytorch_conv.py, in float32 on the run-time dispatched kernels:
//   RGB-D 4 x 48 x 64 -> conv 16 (3x3, stride 2, pad 1) -> conv 32 (same) -> conv 32 (same),
//   SiLU after each -> flatten (32 x 6 x 8 = 1536) -> 256 -> 256 -> 24 (SiLU), MSE to a target,
//   Adam (lr 1e-3) on the encoder's and the MLP's parameters;
// at batch 64 and 256 (items/s = training samples/s), forward and backward one slice of
// kImageTrainSlice samples at a time as the image head trains, on 1 and 2 threads (SliceTeam),
// and the encoder's forward alone.
// BM_default_encoder_train_step: the same step on the image policies' default encoder
// (experiments::Insert3dImageSettings: two cameras' normals and depth, 6 x 48 x 64 -> conv 8,
// 16, 16, 16, the same 3 x 3 stride-2 layers -> 16 x 3 x 4 = 192 -> 256 -> 256 -> 24), whose
// first layer has 8 filters.
// Numbers and commands: docs/BENCHMARKS.md, "Image encoder".
#include <benchmark/benchmark.h>

#include <algorithm>
#include <random>
#include <vector>

#include "handcentric/core/sampling.hpp"
#include "handcentric/policy/adam.hpp"
#include "handcentric/policy/conv_encoder.hpp"
#include "handcentric/policy/mlp.hpp"
#include "handcentric/policy/slice_team.hpp"

using namespace handcentric;
using namespace handcentric::policy;

namespace {

const ImageShape kImage{4, 48, 64};
const std::vector<ConvLayerSpec> kLayers = {{16, 3, 2, 1}, {32, 3, 2, 1}, {32, 3, 2, 1}};
const ImageShape kDefaultImage{6, 48, 64};
const std::vector<ConvLayerSpec> kDefaultLayers = {
    {8, 3, 2, 1}, {16, 3, 2, 1}, {16, 3, 2, 1}, {16, 3, 2, 1}};

Eigen::MatrixXf random_matrix(Eigen::Index rows, Eigen::Index cols, std::mt19937_64& rng) {
  Eigen::MatrixXf m(rows, cols);
  for (Eigen::Index i = 0; i < m.size(); ++i) m(i) = static_cast<float>(standard_normal(rng));
  return m;
}

// The image head's step (image_flow_head.cpp): forward and backward one slice of `slice`
// samples at a time on `threads` lanes (SliceTeam: lane 0 on the network itself, the others on
// copies whose weights are refreshed at each step), the gradients summed in slice order, one Adam
// step; slice = batch is the step on the whole batch at once.
void train_steps(benchmark::State& state, const ImageShape& image,
                 const std::vector<ConvLayerSpec>& layers, int slice, int threads) {
  const int batch = static_cast<int>(state.range(0));
  std::mt19937_64 rng(1);
  ConvEncoder encoder(image, layers);
  encoder.initialize(rng);
  Mlp mlp({static_cast<int>(encoder.output_size()), 256, 256, 24}, Activation::silu);
  mlp.initialize(rng);
  Adam encoder_adam(encoder.parameter_count(), {}), mlp_adam(mlp.parameter_count(), {});
  const Eigen::MatrixXf images = random_matrix(image.size(), batch, rng);
  const Eigen::MatrixXf target = random_matrix(24, batch, rng);
  struct Copy {
    ConvEncoder encoder;
    Mlp mlp;
  };
  std::vector<Copy> copies(static_cast<std::size_t>(threads - 1), Copy{encoder, mlp});
  const auto lane_encoder = [&](int lane) -> ConvEncoder& {
    return lane == 0 ? encoder : copies[static_cast<std::size_t>(lane - 1)].encoder;
  };
  const auto lane_mlp = [&](int lane) -> Mlp& {
    return lane == 0 ? mlp : copies[static_cast<std::size_t>(lane - 1)].mlp;
  };
  std::vector<Eigen::MatrixXf> d_outputs(static_cast<std::size_t>(threads));
  Eigen::VectorXf mlp_gradient, encoder_gradient;
  const auto d_scale = static_cast<float>(2.0 / static_cast<double>(target.size()));  // MSE
  SliceTeam team(threads);
  const SliceTeam::Compute compute = [&](int lane, long first, long count) {
    Mlp& lane_network = lane_mlp(lane);
    Eigen::MatrixXf& d_output = d_outputs[static_cast<std::size_t>(lane)];
    const Eigen::MatrixXf& output =
        lane_network.forward(lane_encoder(lane).forward(images.middleCols(first, count)));
    d_output = (output - target.middleCols(first, count)) * d_scale;
    lane_encoder(lane).backward_parameters(lane_network.backward(d_output));
  };
  const SliceTeam::Add add = [&](int lane, long first) {
    if (first == 0) {
      mlp_gradient = lane_mlp(lane).gradient();
      encoder_gradient = lane_encoder(lane).gradient();
    } else {
      mlp_gradient += lane_mlp(lane).gradient();
      encoder_gradient += lane_encoder(lane).gradient();
    }
  };
  for (auto _ : state) {
    for (Copy& copy : copies) {
      copy.encoder.parameters() = encoder.parameters();
      copy.mlp.parameters() = mlp.parameters();
    }
    team.run(batch, slice, compute, add);
    mlp_adam.step(mlp.parameters(), mlp_gradient);
    encoder_adam.step(encoder.parameters(), encoder_gradient);
    benchmark::DoNotOptimize(encoder.parameters().data());
  }
  state.SetItemsProcessed(state.iterations() * batch);
}

// Arguments: batch, threads.
void BM_conv_train_step(benchmark::State& state) {
  train_steps(state, kImage, kLayers, kImageTrainSlice, static_cast<int>(state.range(1)));
}
void BM_default_encoder_train_step(benchmark::State& state) {
  train_steps(state, kDefaultImage, kDefaultLayers, kImageTrainSlice,
              static_cast<int>(state.range(1)));
}
// The step of the default encoder on one thread with slices of state.range(1) samples (the
// whole batch at 0): how kImageTrainSlice was chosen.
void BM_sliced_default_encoder_train_step(benchmark::State& state) {
  const int slice = static_cast<int>(state.range(1));
  train_steps(state, kDefaultImage, kDefaultLayers,
              slice > 0 ? slice : static_cast<int>(state.range(0)), 1);
}
// Wall time (UseRealTime), as PyTorch's side measures: on a shared machine the CPU time would
// leave out the waits for a core that PyTorch's rate includes. The CPU time Google Benchmark
// reports is the main thread's: per CPU second only on one thread.
BENCHMARK(BM_conv_train_step)
    ->ArgsProduct({{64, 256}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0)
    ->UseRealTime();
BENCHMARK(BM_default_encoder_train_step)
    ->ArgsProduct({{64, 256}, {1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0)
    ->UseRealTime();
BENCHMARK(BM_sliced_default_encoder_train_step)
    ->ArgsProduct({{64, 256}, {0, 8, 16, 32, 64}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0)
    ->UseRealTime();

void BM_conv_encoder_forward(benchmark::State& state) {
  const int batch = static_cast<int>(state.range(0));
  std::mt19937_64 rng(2);
  ConvEncoder encoder(kImage, kLayers);
  encoder.initialize(rng);
  const Eigen::MatrixXf images = random_matrix(kImage.size(), batch, rng);
  for (auto _ : state) benchmark::DoNotOptimize(encoder.forward(images).data());
  state.SetItemsProcessed(state.iterations() * batch);
}
BENCHMARK(BM_conv_encoder_forward)->Arg(256)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
