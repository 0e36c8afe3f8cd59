// Benchmarks of the 2D insertion sim (docs/BENCHMARKS.md, "## Sim"): exact collision queries,
// continuous motion checks, the expert, and rollouts (demos replayed through the rollout loop,
// and the closed-loop expert).
#include <benchmark/benchmark.h>

#include <random>

#include "handcentric/core/sampling.hpp"
#include "handcentric/sim/collision.hpp"
#include "handcentric/sim/expert.hpp"
#include "handcentric/sim/policies.hpp"
#include "handcentric/sim/rollout.hpp"

using namespace handcentric;
using namespace handcentric::sim;

namespace {

/// Hand poses near the hole (within 12 cm, +-45 deg): a mix of free, touching and deep poses.
std::vector<RigidTransform> poses_near_the_hole(int n) {
  std::mt19937_64 rng(1);
  std::vector<RigidTransform> poses;
  for (int i = 0; i < n; ++i) {
    poses.push_back(RigidTransform::planar((uniform01(rng) - 0.5) * 1.57,
                                           12.0 * uniform01(rng) - 6.0, 14.0 * uniform01(rng)));
  }
  return poses;
}

void BM_CollisionQuery(benchmark::State& state) {
  const CollisionChecker checker;
  const auto poses = poses_near_the_hole(1024);
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(checker.collides(poses[i++ & 1023]));
  state.SetItemsProcessed(state.iterations());  // items/s = collision queries per second
}
BENCHMARK(BM_CollisionQuery);

void BM_MotionCheckInsertionStep(benchmark::State& state) {
  // one 0.5 cm control step down the hole, 0.05 from both walls: the expensive case
  const CollisionChecker checker;
  const RigidTransform from = RigidTransform::planar(0.0, 0.0, 5.0),
                       to = RigidTransform::planar(0.0, 0.0, 4.5);
  for (auto _ : state) benchmark::DoNotOptimize(checker.motion_collides(from, to));
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_MotionCheckInsertionStep);

void BM_ExpertDemo(benchmark::State& state) {
  const CollisionChecker checker;
  const auto scenes = sample_scenes(SceneDistribution::train(), 64, 1);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(expert_demo(scenes[i & 63], 1, i & 63, checker));
    ++i;
  }
  state.SetItemsProcessed(state.iterations());  // demos per second
}
BENCHMARK(BM_ExpertDemo)->Unit(benchmark::kMillisecond);

void BM_RolloutReplayedExpert(benchmark::State& state) {
  // the expert's demos replayed through the closed-loop rollout loop (H = 2, K = 16, 8 executed)
  const CollisionChecker checker;
  const auto scenes = sample_scenes(SceneDistribution::train(), 64, 1);
  const ExpertRun run = expert_demos(scenes, 1, checker);
  std::vector<ReplayPolicy> policies;
  for (const Demo& demo : run.demos) policies.emplace_back(demo);
  std::size_t i = 0;
  for (auto _ : state) {
    const std::size_t k = i++ % policies.size();
    benchmark::DoNotOptimize(rollout(policies[k], scenes[k], checker, k));
  }
  state.SetItemsProcessed(state.iterations());  // rollouts per second
}
BENCHMARK(BM_RolloutReplayedExpert)->Unit(benchmark::kMillisecond);

void BM_RolloutClosedLoopExpert(benchmark::State& state) {
  const CollisionChecker checker;
  const ExpertPolicy expert;
  const auto scenes = sample_scenes(SceneDistribution::train(), 64, 1);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(rollout(expert, scenes[i & 63], checker, i));
    ++i;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RolloutClosedLoopExpert)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
