// Policy speed: training throughput of the flow head on the anchor network of
// bench/vs_pytorch.sh, 57 inputs (24 noisy action + 1 time + 32 observation) -> 256 -> 256 -> 256
// -> 24, SiLU, Adam, batch 256; the C8 baseline's training step (c8ddpm) with and without its
// encoded set; and sampling latency at batch 1 (10 Euler steps). Numbers are
// recorded in docs/BENCHMARKS.md ("## Policy") with the commands that produced them.
#include <benchmark/benchmark.h>
#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include <random>
#include <vector>

#include "handcentric/core/representations.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/policy/c8_planar.hpp"
#include "handcentric/policy/head.hpp"
#include "handcentric/policy/mlp.hpp"
#include "handcentric/policy/trainer.hpp"

using namespace handcentric;
using namespace handcentric::policy;

namespace {

PolicyConfig anchor_config(HeadKind head) {
  PolicyConfig config;
  config.head = head;
  config.representation = head == HeadKind::c8flow ? "absolute" : "hand_centric";
  config.action_dimension = 24;
  config.observation_dimension = 32;
  config.time_embedding = 0;  // t itself: the 57-input anchor network
  config.hidden_width = 256;
  config.hidden_layers = 3;
  config.batch_size = 256;
  config.euler_steps = 10;
  config.chunk_length = 4;
  config.history_length = 2;
  if (head == HeadKind::c8flow) {  // an absolute layout needs 6 (H + 1) + 3 (points): 18 + 6 + 9
    config.hand_points = 2;
    config.world_points = 3;
    config.observation_dimension = 33;
  }
  return config;
}

Eigen::MatrixXd random_matrix(Eigen::Index rows, Eigen::Index cols, std::mt19937_64& rng) {
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index i = 0; i < m.size(); ++i) m(i) = standard_normal(rng);
  return m;
}

void BM_flow_train_step_batch256(benchmark::State& state) {
  const PolicyConfig config = anchor_config(HeadKind::flow);
  std::mt19937_64 rng(1);
  const Eigen::MatrixXd actions = random_matrix(24, 4096, rng),
                        observations = random_matrix(32, 4096, rng);
  auto head = make_head(config);
  head->prepare(actions, observations, rng);
  const Eigen::MatrixXf batch_a = actions.leftCols(256).cast<float>();
  const Eigen::MatrixXf batch_o = observations.leftCols(256).cast<float>();
  for (auto _ : state) benchmark::DoNotOptimize(head->train_step(batch_a, batch_o, rng));
  state.SetItemsProcessed(state.iterations() * 256);  // items/s = training samples/s
}
BENCHMARK(BM_flow_train_step_batch256)->Unit(benchmark::kMillisecond)->MinTime(2.0);

// The planar C8 head of Table 1's c8_centre row (c8ddpm, the library's defaults: K = 16, one
// observed pose and 2 eye-in-hand points), one training step at batch 256 as the trainer makes
// it (train_step_on: the columns' encoding looked up) and as it was made before (train_step on
// the copied columns: each column encoded again at every draw).
void c8ddpm_train_step(benchmark::State& state, bool on_the_set) {
  PolicyConfig config;
  config.head = HeadKind::c8ddpm;
  config.representation = "absolute";
  config.hand_points = 2;
  const c8::Layout actions_layout = c8::action_layout(config);
  const c8::Layout observations_layout = c8::observation_layout(config);
  config.action_dimension = actions_layout.absolute_size();
  config.observation_dimension = observations_layout.absolute_size();
  std::mt19937_64 rng(3);
  // Planar absolute columns: every pose block (x, y, z, 0, 0, theta).
  const auto planar_columns = [&rng](const c8::Layout& layout, Eigen::Index n) {
    Eigen::MatrixXd m(layout.absolute_size(), n);
    for (Eigen::Index i = 0; i < m.size(); ++i) m(i) = standard_normal(rng);
    for (int p = 0; p < layout.poses; ++p) m.middleRows(6 * p + 3, 2).setZero();
    return m;
  };
  const Eigen::MatrixXd actions = planar_columns(actions_layout, 4096);
  const Eigen::MatrixXd observations = planar_columns(observations_layout, 4096);
  auto head = make_head(config);
  head->prepare(actions, observations, rng);
  const Eigen::MatrixXf set_actions = actions.cast<float>();
  const Eigen::MatrixXf set_observations = observations.cast<float>();
  std::vector<Eigen::Index> columns(256);
  Eigen::MatrixXf batch_actions(set_actions.rows(), 256);
  Eigen::MatrixXf batch_observations(set_observations.rows(), 256);
  for (auto _ : state) {
    for (std::size_t j = 0; j < columns.size(); ++j) {
      columns[j] = static_cast<Eigen::Index>(rng() % 4096);
      batch_actions.col(static_cast<Eigen::Index>(j)) = set_actions.col(columns[j]);
      batch_observations.col(static_cast<Eigen::Index>(j)) = set_observations.col(columns[j]);
    }
    benchmark::DoNotOptimize(
        on_the_set ? head->train_step_on(Minibatch{set_actions, set_observations, columns,
                                                   batch_actions, batch_observations},
                                         rng)
                   : head->train_step(batch_actions, batch_observations, rng));
  }
  state.SetItemsProcessed(state.iterations() * 256);
}
void BM_c8ddpm_train_step_batch256(benchmark::State& state) {
  c8ddpm_train_step(state, true);
}
void BM_c8ddpm_train_step_reencoding_every_draw_batch256(benchmark::State& state) {
  c8ddpm_train_step(state, false);
}
BENCHMARK(BM_c8ddpm_train_step_batch256)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_c8ddpm_train_step_reencoding_every_draw_batch256)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);

void sample_batch1(benchmark::State& state, HeadKind kind) {
  const PolicyConfig config = anchor_config(kind);
  std::mt19937_64 rng(2);
  const Eigen::MatrixXd actions = random_matrix(24, 512, rng);
  const Eigen::MatrixXd observations = random_matrix(config.observation_dimension, 512, rng);
  auto head = make_head(config);
  head->prepare(actions, observations, rng);
  const Eigen::MatrixXf o = observations.col(0).cast<float>();
  for (auto _ : state) benchmark::DoNotOptimize(head->sample(o, rng));
}
void BM_flow_sample_10_euler_steps_batch1(benchmark::State& state) {
  sample_batch1(state, HeadKind::flow);
}
void BM_ddpm_sample_10_ddim_steps_batch1(benchmark::State& state) {
  sample_batch1(state, HeadKind::ddpm);
}
void BM_cvae_sample_batch1(benchmark::State& state) {
  sample_batch1(state, HeadKind::cvae);
}
void BM_c8flow_sample_10_euler_steps_batch1(benchmark::State& state) {
  sample_batch1(state, HeadKind::c8flow);
}
BENCHMARK(BM_flow_sample_10_euler_steps_batch1)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ddpm_sample_10_ddim_steps_batch1)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_cvae_sample_batch1)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_c8flow_sample_10_euler_steps_batch1)->Unit(benchmark::kMicrosecond);

#if defined(__x86_64__)
// The host's speed probe: AVX-512 FMAs on 24 independent registers, no memory traffic. Its
// GFLOP/s (items/s x 1e-9) is the ceiling of the training kernels at that moment; on a shared
// host it drifts (docs/BENCHMARKS.md), so it is run beside the numbers it qualifies.
// noipa keeps GCC from folding the loop into the caller's constants; clang has no noipa, and
// noinline does that there.
#if defined(__clang__)
#define HANDCENTRIC_NO_INTERPROCEDURAL noinline
#else
#define HANDCENTRIC_NO_INTERPROCEDURAL noipa
#endif
__attribute__((target("avx512f"), HANDCENTRIC_NO_INTERPROCEDURAL)) float fma_probe(
    long iterations) {
  __m512 acc[24];
  for (int i = 0; i < 24; ++i) acc[i] = _mm512_set1_ps(0.001f * static_cast<float>(i));
  const __m512 x = _mm512_set1_ps(0.999f), y = _mm512_set1_ps(1e-4f);
  for (long it = 0; it < iterations; ++it) {
#pragma GCC unroll 24
    for (int i = 0; i < 24; ++i) acc[i] = _mm512_fmadd_ps(acc[i], x, y);
  }
  __m512 sum = acc[0];
  for (int i = 1; i < 24; ++i) sum = _mm512_add_ps(sum, acc[i]);
  alignas(64) float lanes[16];
  _mm512_store_ps(lanes, sum);  // (not _mm512_reduce_add_ps: GCC 12 warns inside it)
  float total = 0.0f;
  for (float lane : lanes) total += lane;
  return total;
}

void BM_avx512_fma_peak(benchmark::State& state) {
  if (!__builtin_cpu_supports("avx512f")) {
    state.SkipWithError("no AVX-512 on this CPU");
    return;
  }
  constexpr long kIterations = 1 << 20;
  long iterations = kIterations;
  benchmark::DoNotOptimize(iterations);  // opaque: the loop cannot be folded
  for (auto _ : state) benchmark::DoNotOptimize(fma_probe(iterations));
  state.SetItemsProcessed(state.iterations() * kIterations * 24 *
                          32);  // flops: 24 FMAs x 16 lanes x 2
}
BENCHMARK(BM_avx512_fma_peak)->Unit(benchmark::kMillisecond);
#endif

// One network evaluation at batch 1 (the inner loop of sampling): 57 -> 256 -> 256 -> 256 -> 24.
void BM_mlp_infer_batch1(benchmark::State& state) {
  Mlp mlp({57, 256, 256, 256, 24}, Activation::silu);
  std::mt19937_64 rng(5);
  mlp.initialize(rng);
  Eigen::MatrixXf input = Eigen::MatrixXf::Random(57, 1), output, scratch[2];
  for (auto _ : state) {
    mlp.infer(input, output, scratch);
    input(0, 0) = output(0, 0) * 1e-3f;  // a dependency, as between Euler steps
  }
  state.SetBytesProcessed(state.iterations() * mlp.parameter_count() *
                          4);  // bytes/s = weight bytes read
}
BENCHMARK(BM_mlp_infer_batch1)->Unit(benchmark::kMicrosecond);

// The whole outer policy at the paper's defaults (K = 16, H = 2, two eye-in-hand points):
// encode, 10 Euler steps, decode. The network is 64 + 16 inputs wide here (96 action +
// 16 time features + 22 observation), as `handcentric train` builds it.
void BM_hand_centric_flow_act_K16(benchmark::State& state) {
  std::mt19937_64 rng(3);
  std::vector<Scene> scenes;
  for (int i = 0; i < 64; ++i) scenes.push_back(random_scene(rng, 2, 16, 2, 0, 1.0));
  PolicyConfig config;
  config.steps = 1;
  const LearnedPolicy policy = train_policy(config, scenes, 4);
  std::uint64_t seed = 0;
  for (auto _ : state) benchmark::DoNotOptimize(policy.act(scenes[0], ++seed));
}
BENCHMARK(BM_hand_centric_flow_act_K16)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
