// Geometry micro benchmarks, each beside Eigen's own equivalent in the same run:
//   compose          vs Eigen::Isometry3d * Isometry3d
//   inverse_compose  vs Isometry3d::inverse(Isometry) * Isometry3d
//   so3::log         vs Eigen::AngleAxisd(matrix)       (rotation vector from a matrix)
//   so3::exp         vs Eigen::AngleAxisd::toRotationMatrix(), from a stored angle-axis and from
//                    the same rotation vector (like for like: norm and axis included)
//   hand_centric encode_actions, K = 16, H = 2
// Inputs cycle through 1024 seeded Haar-random values so the branch predictor and the cache
// see realistic data. Run: build/bench/bench_geometry --benchmark_repetitions=5
//   --benchmark_report_aggregates_only=true   (see docs/BENCHMARKS.md)
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "handcentric/core/representations.hpp"
#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/core/so3.hpp"

namespace {

using namespace handcentric;
constexpr std::size_t kInputs = 1024;

struct Inputs {
  std::vector<RigidTransform> transforms;
  std::vector<Eigen::Isometry3d> isometries;
  std::vector<Eigen::Matrix3d> matrices;
  std::vector<Eigen::Vector3d> rotation_vectors;
  std::vector<Eigen::AngleAxisd> angle_axes;
  Inputs() {
    std::mt19937_64 rng(42);
    for (std::size_t i = 0; i < kInputs; ++i) {
      const RigidTransform T = random_transform(rng, 10.0);
      transforms.push_back(T);
      Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
      iso.linear() = T.rotation().matrix();
      iso.translation() = T.translation();
      isometries.push_back(iso);
      matrices.push_back(T.rotation().matrix());
      rotation_vectors.push_back(T.rotation().log());
      angle_axes.emplace_back(T.rotation().matrix());
    }
  }
};

const Inputs& inputs() {
  static const Inputs data;
  return data;
}

void compose(benchmark::State& state) {
  const auto& in = inputs().transforms;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(in[i % kInputs] * in[(i + 1) % kInputs]);
    ++i;
  }
}
BENCHMARK(compose);

void eigen_isometry_product(benchmark::State& state) {
  const auto& in = inputs().isometries;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(in[i % kInputs] * in[(i + 1) % kInputs]);
    ++i;
  }
}
BENCHMARK(eigen_isometry_product);

void inverse_compose(benchmark::State& state) {
  const auto& in = inputs().transforms;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(in[i % kInputs].inverse_compose(in[(i + 1) % kInputs]));
    ++i;
  }
}
BENCHMARK(inverse_compose);

void eigen_isometry_inverse_product(benchmark::State& state) {
  const auto& in = inputs().isometries;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(in[i % kInputs].inverse(Eigen::Isometry) * in[(i + 1) % kInputs]);
    ++i;
  }
}
BENCHMARK(eigen_isometry_inverse_product);

void so3_log(benchmark::State& state) {
  const auto& in = inputs().matrices;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(so3::log(in[i % kInputs]));
    ++i;
  }
}
BENCHMARK(so3_log);

void eigen_angleaxis_from_matrix(benchmark::State& state) {
  const auto& in = inputs().matrices;
  std::size_t i = 0;
  for (auto _ : state) {
    const Eigen::AngleAxisd aa(in[i % kInputs]);
    benchmark::DoNotOptimize(Eigen::Vector3d(aa.angle() * aa.axis()));
    ++i;
  }
}
BENCHMARK(eigen_angleaxis_from_matrix);

void so3_exp(benchmark::State& state) {
  const auto& in = inputs().rotation_vectors;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(so3::exp(in[i % kInputs]));
    ++i;
  }
}
BENCHMARK(so3_exp);

void eigen_angleaxis_to_matrix(benchmark::State& state) {
  const auto& in = inputs().angle_axes;
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(in[i % kInputs].toRotationMatrix());
    ++i;
  }
}
BENCHMARK(eigen_angleaxis_to_matrix);

// Like for like with so3::exp: Eigen from the same rotation vector (norm and axis included).
void eigen_angleaxis_from_rotation_vector_to_matrix(benchmark::State& state) {
  const auto& in = inputs().rotation_vectors;
  std::size_t i = 0;
  for (auto _ : state) {
    const Eigen::Vector3d& r = in[i % kInputs];
    const double angle = r.norm();
    benchmark::DoNotOptimize(Eigen::AngleAxisd(angle, r / angle).toRotationMatrix());
    ++i;
  }
}
BENCHMARK(eigen_angleaxis_from_rotation_vector_to_matrix);

void hand_centric_encode_K16_H2(benchmark::State& state) {
  std::mt19937_64 rng(7);
  const Scene scene = random_scene(rng, 2, 16, 2, 0, 10.0);
  const HandCentricRepresentation representation;
  for (auto _ : state) benchmark::DoNotOptimize(representation.encode_actions(scene));
}
BENCHMARK(hand_centric_encode_K16_H2);

}  // namespace

BENCHMARK_MAIN();
