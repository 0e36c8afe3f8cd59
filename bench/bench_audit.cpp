// The audit's speed: the whole built-in audit (four representations and ActionFlow's target,
// all groups, both modes, both views, 1000 cases) should take under 2 s, and an
// --exec audit should spend its time in the plug-in, not in the pipe. Figures and the exact
// command: docs/BENCHMARKS.md, "Audit".
#include <benchmark/benchmark.h>

#include <memory>
#include <random>
#include <string>

#include "handcentric/core/representations.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/props/audit.hpp"
#include "handcentric/props/transport/pipe_representation.hpp"

namespace {

using namespace handcentric;

// bench/, from this file's path (the benchmark finds the example plug-in beside it).
std::string source_dir() {
  const std::string file = __FILE__;
  return file.substr(0, file.find_last_of('/'));
}

// The whole built-in audit, as `handcentric audit` runs it (state.range(0) cases per cell).
void BM_builtin_audit(benchmark::State& state) {
  props::AuditOptions options;
  options.cases = static_cast<int>(state.range(0));
  for (auto _ : state) {
    auto results = props::audit_builtins({}, options);
    benchmark::DoNotOptimize(results);
  }
}
BENCHMARK(BM_builtin_audit)->Arg(1000)->Unit(benchmark::kMillisecond)->Iterations(3);

// One representation's audit, to see where the time goes.
void BM_audit_one(benchmark::State& state, const std::string& name) {
  props::AuditOptions options;
  for (auto _ : state) {
    auto results = props::audit_builtins({name}, options);
    benchmark::DoNotOptimize(results);
  }
}
BENCHMARK_CAPTURE(BM_audit_one, absolute, std::string("absolute"))
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);
BENCHMARK_CAPTURE(BM_audit_one, hand_centric, std::string("hand_centric"))
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);
BENCHMARK_CAPTURE(BM_audit_one, actionflow, std::string("actionflow"))
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

// The pipe's own cost: a plug-in that answers at once (three lines of Python that copy the id
// and send six zeros), per round trip with a scene of H = 2, K = 16; compare with
// BM_builtin_encode. Counter pipe_share: the part of ask() not spent waiting for the plug-in.
void BM_pipe_round_trip(benchmark::State& state) {
  const props::PipeRepresentation plugin(
      "python3 -c 'import sys\nfor line in sys.stdin:\n  print(\"{\" + line[1:line.index(\",\")] + "
      "\", \\\"actions\\\": [0, 0, 0, 0, 0, 0]}\", flush=True)'",
      10.0);
  std::mt19937_64 rng(1);
  std::uint64_t i = 0;
  plugin.encode_actions(
      random_scene(rng, 2, 16, 2, 0, 10.0));  // warm up: Python's start is not the pipe's
  const double asking0 = plugin.seconds_asking(), waiting0 = plugin.seconds_waiting();
  for (auto _ : state) {
    Scene scene = random_scene(rng, 2, 16, 2, 0, 10.0);
    scene.world_T_hand_history[0] =
        RigidTransform::from_translation(Eigen::Vector3d(static_cast<double>(++i), 0, 0));
    benchmark::DoNotOptimize(plugin.encode_actions(scene));  // a new scene: never from the cache
  }
  state.counters["pipe_share"] =
      1.0 - (plugin.seconds_waiting() - waiting0) / (plugin.seconds_asking() - asking0);
}
BENCHMARK(BM_pipe_round_trip)->Unit(benchmark::kMicrosecond);

// An --exec audit of the Python example (100 cases per cell, se3): the share of the time in
// ask() that is the pipe's (formatting, writing, parsing) rather than the plug-in's.
void BM_exec_audit_python_example(benchmark::State& state) {
  for (auto _ : state) {
    auto plugin = std::make_shared<props::PipeRepresentation>(
        "python3 " + source_dir() + "/../examples/python_representation/repr.py", 10.0);
    props::AuditOptions options;
    options.cases = 100;
    options.groups = {props::Group::se3};
    auto result = props::classify_representation(plugin, props::classifier_options(options));
    benchmark::DoNotOptimize(result);
    state.counters["requests"] = plugin->requests_sent();
    state.counters["pipe_share"] = 1.0 - plugin->seconds_waiting() / plugin->seconds_asking();
  }
}
BENCHMARK(BM_exec_audit_python_example)->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_builtin_encode(benchmark::State& state) {
  const HandCentricRepresentation hand_centric;
  std::mt19937_64 rng(1);
  const Scene scene = random_scene(rng, 2, 16, 2, 0, 10.0);
  for (auto _ : state) benchmark::DoNotOptimize(hand_centric.encode_actions(scene));
}
BENCHMARK(BM_builtin_encode)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
