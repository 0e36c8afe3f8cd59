// The floor under batch-1 sampling (issue 5's goal: 10 Euler steps of the anchor network,
// 57 -> 256 -> 256 -> 256 -> 24, in <= 30 us), and three designs that could lower it. None of this
// is library code: these are measurements that back a decision, recorded in docs/BENCHMARKS.md
// ("Why 30 us at batch 1 is out of reach").
//
// - BM_l2_read_weights_10_times: a plain vector sum over the 607 KB of float32 weights, ten times.
//   Ten Euler steps must read every weight ten times, in order, with no reuse between steps, so
//   this is the one-core floor of float32 sampling before any arithmetic.
// - BM_amx_bf16_weights_sample: one core, the weights rounded to bfloat16 (half the bytes) and
//   multiplied by AMX tiles; each activation is split exactly into three bfloat16 parts
//   (hi + mid + lo = x), so the weights are the only rounding.
// - BM_two_core_float32_sample: the rows of each hidden layer split between the two cores (each
//   keeps its half of the weights in its own L2; both evaluate the small last layer) with a spin
//   barrier after each split layer: 30 cross-core exchanges per sample. The float32 network.
// - BM_two_core_amx_bf16_weights_sample: both of the above at once.
// Each prototype reports max_abs_error, the largest difference of its sampled chunk from the
// float32 network's (plain loops, std::exp) for the same noise and observation.
//
// The prototypes use the library's SiLU kernel, and the float32 one its batch-1 product
// (policy/src/kernels, the private interface that tests/policy and bench_kernels also use).
#include <benchmark/benchmark.h>

#if defined(__x86_64__) && defined(__linux__)
#include <immintrin.h>
#include <pthread.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cpuid.h>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <random>
#include <thread>
#include <vector>

#include "kernels/kernel_set.hpp"

namespace kernels = handcentric::policy::kernels;

namespace {

constexpr int kSteps = 10;
constexpr int kIn = 57, kHidden = 256, kOut = 24, kAction = 24;

struct FreeDeleter {
  void operator()(void* p) const { std::free(p); }
};
template <typename T>
using Aligned = std::unique_ptr<T[], FreeDeleter>;

template <typename T>
Aligned<T> aligned_zeros(std::size_t n) {
  const std::size_t bytes = (n * sizeof(T) + 63) / 64 * 64;
  Aligned<T> p(static_cast<T*>(std::aligned_alloc(64, bytes)));
  std::memset(p.get(), 0, bytes);
  return p;
}

// The anchor network with seeded weights, column-major (rows = outputs), in float32.
struct Network {
  int widths[5] = {kIn, kHidden, kHidden, kHidden, kOut};
  std::vector<std::vector<float>> w, b;  // w[l]: widths[l+1] x widths[l], column-major
  explicit Network(std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    for (int l = 0; l < 4; ++l) {
      std::normal_distribution<float> normal(0.0f, 1.0f / std::sqrt(static_cast<float>(widths[l])));
      w.emplace_back(static_cast<std::size_t>(widths[l]) * widths[l + 1]);
      b.emplace_back(widths[l + 1]);
      for (float& x : w.back()) x = normal(rng);
      for (float& x : b.back()) x = 0.1f * normal(rng);
    }
  }
};

float silu(float z) { return z / (1.0f + std::exp(-z)); }


// The network's input at Euler step n: [x (24), t, observation (32)].
void input_at(const float* x, int n, const float* observation, float* input) {
  std::copy(x, x + kAction, input);
  input[kAction] = static_cast<float>(n) / kSteps;
  std::copy(observation, observation + (kIn - kAction - 1), input + kAction + 1);
}

// Reference: the float32 network, 10 Euler steps, plain loops (for the AMX error only).
void sample_reference(const Network& net, const float* noise, const float* observation, float* x) {
  std::copy(noise, noise + kAction, x);
  std::vector<float> h(kIn), next;
  for (int n = 0; n < kSteps; ++n) {
    h.resize(kIn);
    input_at(x, n, observation, h.data());
    for (int l = 0; l < 4; ++l) {
      next.assign(net.b[l].begin(), net.b[l].end());
      for (int k = 0; k < net.widths[l]; ++k) {
        for (int i = 0; i < net.widths[l + 1]; ++i) next[i] += net.w[l][static_cast<std::size_t>(k) * net.widths[l + 1] + i] * h[k];
      }
      if (l < 3) std::transform(next.begin(), next.end(), next.begin(), silu);
      h.swap(next);
    }
    for (int i = 0; i < kAction; ++i) x[i] += h[i] / kSteps;
  }
}

// ---------------------------------------------------------------------------------------------
// One-core float32 floor.

__attribute__((target("avx512f"), noipa)) float read_sum(const float* a, long n) {
  __m512 s0 = _mm512_setzero_ps(), s1 = s0, s2 = s0, s3 = s0;
  for (long i = 0; i < n; i += 64) {
    s0 = _mm512_add_ps(s0, _mm512_load_ps(a + i));
    s1 = _mm512_add_ps(s1, _mm512_load_ps(a + i + 16));
    s2 = _mm512_add_ps(s2, _mm512_load_ps(a + i + 32));
    s3 = _mm512_add_ps(s3, _mm512_load_ps(a + i + 48));
  }
  alignas(64) float lanes[16];
  _mm512_store_ps(lanes, _mm512_add_ps(_mm512_add_ps(s0, s1), _mm512_add_ps(s2, s3)));
  float total = 0;
  for (float lane : lanes) total += lane;
  return total;
}

void BM_l2_read_weights_10_times(benchmark::State& state) {
  if (!__builtin_cpu_supports("avx512f")) return state.SkipWithError("no AVX-512 on this CPU");
  const long floats = static_cast<long>(kIn) * kHidden + 2L * kHidden * kHidden + kHidden * kOut + 3 * kHidden + kOut;
  const long padded = (floats + 63) / 64 * 64;
  Aligned<float> weights = aligned_zeros<float>(padded);
  for (long i = 0; i < floats; ++i) weights[i] = 1e-3f * static_cast<float>(i % 97);
  for (auto _ : state) {
    for (int n = 0; n < kSteps; ++n) benchmark::DoNotOptimize(read_sum(weights.get(), padded));
  }
  state.SetBytesProcessed(state.iterations() * kSteps * padded * 4);
}
BENCHMARK(BM_l2_read_weights_10_times)->Unit(benchmark::kMicrosecond);

// ---------------------------------------------------------------------------------------------
// The layers of the prototypes. A layer keeps rows [r0, r0 + rows) of one of the network's
// layers (all of them, or one core's half) and computes y = SiLU(W x + b) (no SiLU on the last).

// Rows [r0, r0 + rows) of the out x in column-major w, as rows x in column-major.
std::vector<float> rows_of(const std::vector<float>& w, int out, int in, int r0, int rows) {
  std::vector<float> part(static_cast<std::size_t>(rows) * in);
  for (int k = 0; k < in; ++k) {
    for (int i = 0; i < rows; ++i) part[static_cast<std::size_t>(k) * rows + i] = w[static_cast<std::size_t>(k) * out + r0 + i];
  }
  return part;
}

// Float32 through the library's own kernels (the narrow product with the SiLU epilogue that
// FlowHead::sample runs), on rows padded to a multiple of 16 so that every column starts on a
// cache line.
struct Float32Layer {
  int in = 0, rows = 0, padded = 0;
  bool silu = true;
  Aligned<float> w, b;
  Float32Layer(const std::vector<float>& w_part, const std::vector<float>& b_part, int in_, int rows_, bool silu_)
      : in(in_), rows(rows_), padded((rows_ + 15) / 16 * 16), silu(silu_) {
    w = aligned_zeros<float>(static_cast<std::size_t>(padded) * in);
    b = aligned_zeros<float>(padded);
    for (int k = 0; k < in; ++k) std::copy_n(w_part.data() + static_cast<std::size_t>(k) * rows, rows, w.get() + k * padded);
    std::copy(b_part.begin(), b_part.end(), b.get());
  }
  void operator()(const float* x, float* y) const {
    kernels::Gemm product{kernels::Op::none, kernels::Op::none, rows, 1, in, w.get(), padded, x, in, b.get(), y, rows};
    if (silu) product.epilogue = kernels::Epilogue::silu;
    kernels::active().gemm(product);
  }
};

std::uint16_t to_bf16(float f) {  // round to nearest even
  std::uint32_t u;
  std::memcpy(&u, &f, 4);
  u += 0x7FFFu + ((u >> 16) & 1u);
  return static_cast<std::uint16_t>(u >> 16);
}

bool amx_usable() {
  unsigned eax, ebx, ecx, edx;
  if (!__get_cpuid_count(7, 0, &eax, &ebx, &ecx, &edx)) return false;
  const bool tile = (edx >> 24) & 1u, bf16 = (edx >> 22) & 1u;
  constexpr long kArchReqXcompPerm = 0x1023, kXfeatureXtiledata = 18;  // Linux: ask for the tile state
  return tile && bf16 && syscall(SYS_arch_prctl, kArchReqXcompPerm, kXfeatureXtiledata) == 0;
}

struct TileConfig {
  std::uint8_t palette = 1, start_row = 0, reserved[14] = {};
  std::uint16_t bytes_per_row[16] = {};
  std::uint8_t rows[16] = {};
};

// Per thread: C tiles 0-3 and the A tile 4 have 3 rows (hi, mid, lo), B tiles 5-7 16 rows.
__attribute__((target("amx-tile"))) void configure_tiles() {
  TileConfig config;
  for (int t = 0; t < 5; ++t) config.rows[t] = 3, config.bytes_per_row[t] = 64;
  for (int t = 5; t < 8; ++t) config.rows[t] = 16, config.bytes_per_row[t] = 64;
  // GCC 12's _tile_loadconfig tells the compiler it reads only 8 bytes, so without this barrier
  // the stores above are dropped as dead and ldtilecfg faults on garbage.
  asm volatile("" : : "r"(&config) : "memory");
  _tile_loadconfig(&config);
}

__attribute__((target("amx-tile"))) void release_tiles() { _tile_release(); }

// x (in floats) as AMX A tiles of 3 rows x 32 bfloat16: rows hi, mid, lo with hi + mid + lo = x.
__attribute__((target("avx512f,avx512bw,avx512bf16"))) void split_bf16(const float* x, int in, int k_tiles,
                                                                       std::uint16_t* parts) {
  for (int p = 0; p < k_tiles; ++p) {
    for (int half = 0; half < 2; ++half) {
      const int k0 = p * 32 + half * 16, count = std::max(0, std::min(16, in - k0));
      const __mmask16 mask = static_cast<__mmask16>(count >= 16 ? 0xFFFFu : (1u << count) - 1u);
      __m512 rest = _mm512_maskz_loadu_ps(mask, x + k0);
      for (int part = 0; part < 3; ++part) {
        const __m256i bits = reinterpret_cast<__m256i>(_mm512_cvtneps_pbh(rest));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(parts + (p * 3 + part) * 32 + half * 16), bits);
        rest = _mm512_sub_ps(rest, _mm512_castsi512_ps(_mm512_slli_epi32(_mm512_cvtepu16_epi32(bits), 16)));
      }
    }
  }
}

// y(16 outputs) = the sum of the three rows of c (the hi, mid, lo products) + bias.
__attribute__((target("avx512f"))) void sum_parts(const float* c, const float* bias, float* y) {
  const __m512 sum = _mm512_add_ps(_mm512_add_ps(_mm512_load_ps(c), _mm512_load_ps(c + 16)), _mm512_load_ps(c + 32));
  _mm512_storeu_ps(y, _mm512_add_ps(sum, _mm512_load_ps(bias)));
}

// Bfloat16 weights as AMX B tiles: for output tile q (16 outputs) and input tile p (32 inputs),
// 16 rows of 16 pairs (VNNI order: row r holds inputs 2r, 2r + 1 of every output), 1 KB, stored
// in the order the product reads them: groups of 4 output tiles, then p, then the tile in the group.
struct AmxLayer {
  static constexpr int kGroup = 4;
  int in = 0, rows = 0, k_tiles = 0, q_tiles = 0;
  bool silu = true;
  Aligned<std::uint16_t> tiles;
  Aligned<float> bias;
  AmxLayer(const std::vector<float>& w_part, const std::vector<float>& b_part, int in_, int rows_, bool silu_)
      : in(in_), rows(rows_), k_tiles((in_ + 31) / 32), q_tiles((rows_ + 15) / 16), silu(silu_) {
    tiles = aligned_zeros<std::uint16_t>(static_cast<std::size_t>(k_tiles) * q_tiles * 512);
    bias = aligned_zeros<float>(static_cast<std::size_t>(q_tiles) * 16);
    for (int q = 0; q < q_tiles; ++q) {
      const int q0 = q / kGroup * kGroup, group = std::min(kGroup, q_tiles - q0);
      for (int p = 0; p < k_tiles; ++p) {
        std::uint16_t* tile = tiles.get() + (static_cast<std::size_t>(q0) * k_tiles + static_cast<std::size_t>(p) * group + (q - q0)) * 512;
        for (int kk = 0; kk < 32; ++kk) {
          for (int n = 0; n < 16; ++n) {
            const int row = q * 16 + n, col = p * 32 + kk;
            const float value = row < rows && col < in ? w_part[static_cast<std::size_t>(col) * rows + row] : 0.0f;
            tile[(kk / 2) * 32 + n * 2 + kk % 2] = to_bf16(value);
          }
        }
      }
    }
    std::copy(b_part.begin(), b_part.end(), bias.get());
  }
  void operator()(const float* x, float* y) const {
    alignas(64) std::uint16_t parts[8 * 96];
    split_bf16(x, in, k_tiles, parts);
    product(parts, y);
    if (silu) kernels::active().silu(q_tiles * 16, y);
  }
  // C tiles 0-3 accumulate a group of 4 output tiles; A = tile 4; B rotates over tiles 5-7.
  __attribute__((target("amx-tile,amx-bf16"))) void product(const std::uint16_t* parts, float* y) const {
    alignas(64) float c[3 * 16];
    for (int q0 = 0; q0 < q_tiles; q0 += kGroup) {
      const int group = std::min(kGroup, q_tiles - q0);
      _tile_zero(0);
      _tile_zero(1);
      _tile_zero(2);
      _tile_zero(3);
      for (int p = 0; p < k_tiles; ++p) {
        _tile_loadd(4, parts + p * 96, 64);
        const std::uint16_t* base = tiles.get() + (static_cast<std::size_t>(q0) * k_tiles + static_cast<std::size_t>(p) * group) * 512;
        _tile_loadd(5, base, 64);
        _tile_dpbf16ps(0, 4, 5);
        if (group > 1) { _tile_loadd(6, base + 512, 64); _tile_dpbf16ps(1, 4, 6); }
        if (group > 2) { _tile_loadd(7, base + 1024, 64); _tile_dpbf16ps(2, 4, 7); }
        if (group > 3) { _tile_loadd(5, base + 1536, 64); _tile_dpbf16ps(3, 4, 5); }
      }
      const auto store = [&](int i) { sum_parts(c, bias.get() + (q0 + i) * 16, y + (q0 + i) * 16); };
      _tile_stored(0, c, 64);
      store(0);
      if (group > 1) { _tile_stored(1, c, 64); store(1); }
      if (group > 2) { _tile_stored(2, c, 64); store(2); }
      if (group > 3) { _tile_stored(3, c, 64); store(3); }
    }
  }
};

// The fixed noise and observation every prototype samples from.
struct Query {
  alignas(64) float noise[kAction];
  alignas(64) float observation[kIn - kAction - 1];
  Query() {
    for (int i = 0; i < kAction; ++i) noise[i] = std::sin(1.0f + i);
    for (int i = 0; i < kIn - kAction - 1; ++i) observation[i] = std::cos(2.0f + i);
  }
};

float max_abs_error(const Network& net, const Query& query, const float* x) {
  float reference[kAction], error = 0;
  sample_reference(net, query.noise, query.observation, reference);
  for (int i = 0; i < kAction; ++i) error = std::max(error, std::abs(x[i] - reference[i]));
  return error;
}

// ---------------------------------------------------------------------------------------------
// One core: the whole network per layer.

template <typename Layer>
void one_core_sample(const std::vector<Layer>& layers, const Query& query, float* x) {
  alignas(64) float input[64] = {}, h[2][kHidden], out[32];
  std::copy(query.noise, query.noise + kAction, x);
  for (int n = 0; n < kSteps; ++n) {
    input_at(x, n, query.observation, input);
    const float* in = input;
    for (int l = 0; l < 3; ++l) {
      layers[l](in, h[l % 2]);
      in = h[l % 2];
    }
    layers[3](in, out);
    for (int i = 0; i < kAction; ++i) x[i] += out[i] / kSteps;
  }
}

void BM_amx_bf16_weights_sample(benchmark::State& state) {
  if (!__builtin_cpu_supports("avx512f") || !amx_usable()) return state.SkipWithError("no AMX-BF16 here");
  const Network net(7);
  const Query query;
  std::vector<AmxLayer> layers;
  for (int l = 0; l < 4; ++l) layers.emplace_back(net.w[l], net.b[l], net.widths[l], net.widths[l + 1], l < 3);
  configure_tiles();
  alignas(64) float x[kAction];
  for (auto _ : state) {
    one_core_sample(layers, query, x);
    benchmark::DoNotOptimize(x);
  }
  release_tiles();
  state.counters["max_abs_error"] = max_abs_error(net, query, x);
}
BENCHMARK(BM_amx_bf16_weights_sample)->Unit(benchmark::kMicrosecond);

// ---------------------------------------------------------------------------------------------
// Two cores: each core computes its half of the rows of every hidden layer, publishes them, and
// waits at a spin barrier for the other half; both compute the small last layer and the Euler
// step themselves, so there are 3 exchanges per step.

struct alignas(64) Flag {
  std::atomic<long> epoch{0};
};

template <typename Layer>
struct TwoCoreSampler {
  static constexpr int kHalf = kHidden / 2;
  std::vector<Layer> halves[2];  // [core]: 3 hidden halves, then the whole last layer
  alignas(64) float shared[3][kHidden] = {};
  Flag done[2], start;
  std::atomic<bool> quit{false};

  explicit TwoCoreSampler(const Network& net) {
    for (int core = 0; core < 2; ++core) {
      for (int l = 0; l < 3; ++l) {
        const std::vector<float> b(net.b[l].begin() + core * kHalf, net.b[l].begin() + (core + 1) * kHalf);
        halves[core].emplace_back(rows_of(net.w[l], kHidden, net.widths[l], core * kHalf, kHalf), b, net.widths[l], kHalf, true);
      }
      halves[core].emplace_back(net.w[3], net.b[3], kHidden, kOut, false);
    }
  }

  // One sample on `core`; `epoch` counts this core's barriers.
  void sample(int core, long& epoch, const Query& query, float* x) {
    const auto barrier = [&] {
      done[core].epoch.store(++epoch, std::memory_order_release);
      while (done[1 - core].epoch.load(std::memory_order_acquire) < epoch) _mm_pause();
    };
    alignas(64) float input[64] = {}, local[kHidden], out[32];
    std::copy(query.noise, query.noise + kAction, x);
    for (int n = 0; n < kSteps; ++n) {
      input_at(x, n, query.observation, input);
      const float* in = input;
      for (int l = 0; l < 3; ++l) {
        halves[core][l](in, shared[l] + core * kHalf);
        barrier();
        std::memcpy(local, shared[l], sizeof local);
        in = local;
      }
      halves[core][3](local, out);
      for (int i = 0; i < kAction; ++i) x[i] += out[i] / kSteps;
    }
  }
};

bool pin_to_core(int core) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(core, &set);
  return pthread_setaffinity_np(pthread_self(), sizeof set, &set) == 0;
}

// Each iteration is one sample on both cores; `thread_setup` / `thread_teardown` run on each.
template <typename Layer, typename Setup, typename Teardown>
void run_two_cores(benchmark::State& state, Setup thread_setup, Teardown thread_teardown) {
  cpu_set_t before;
  pthread_getaffinity_np(pthread_self(), sizeof before, &before);
  if (!CPU_ISSET(0, &before) || !CPU_ISSET(1, &before)) {  // spinning on one core would crawl
    return state.SkipWithError("needs cores 0 and 1 (run under taskset -c 0,1 or without taskset)");
  }
  const Network net(7);
  const Query query;
  auto sampler = std::make_unique<TwoCoreSampler<Layer>>(net);
  std::thread helper([&] {
    pin_to_core(1);
    thread_setup();
    long barrier_epoch = 0, seen = 0;
    float x[kAction];
    for (;;) {
      long go;
      while ((go = sampler->start.epoch.load(std::memory_order_acquire)) == seen) {
        if (sampler->quit.load(std::memory_order_relaxed)) {
          thread_teardown();
          return;
        }
        _mm_pause();
      }
      seen = go;
      sampler->sample(1, barrier_epoch, query, x);
    }
  });
  pin_to_core(0);
  thread_setup();
  long barrier_epoch = 0, samples = 0;
  float x[kAction];
  for (auto _ : state) {
    sampler->start.epoch.store(++samples, std::memory_order_release);
    sampler->sample(0, barrier_epoch, query, x);
    benchmark::DoNotOptimize(x);
  }
  thread_teardown();
  sampler->quit.store(true);
  helper.join();
  pthread_setaffinity_np(pthread_self(), sizeof before, &before);
  state.counters["max_abs_error"] = max_abs_error(net, query, x);
}

void BM_two_core_float32_sample(benchmark::State& state) {
  if (!__builtin_cpu_supports("avx512f")) return state.SkipWithError("no AVX-512 on this CPU");
  run_two_cores<Float32Layer>(state, [] {}, [] {});
}
BENCHMARK(BM_two_core_float32_sample)->Unit(benchmark::kMicrosecond)->UseRealTime();

void BM_two_core_amx_bf16_weights_sample(benchmark::State& state) {
  if (!__builtin_cpu_supports("avx512f") || !amx_usable()) return state.SkipWithError("no AMX-BF16 here");
  run_two_cores<AmxLayer>(state, configure_tiles, release_tiles);
}
BENCHMARK(BM_two_core_amx_bf16_weights_sample)->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace
#endif

BENCHMARK_MAIN();
