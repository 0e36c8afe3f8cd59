// Kernel selection (kernels.hpp).
#include <array>
#include <atomic>
#include <cstdlib>
#include <mutex>
#include <vector>

#include <hwy/targets.h>

#include "kernel_set.hpp"
#include "handcentric/core/errors.hpp"

namespace handcentric::policy {

std::string to_string(KernelIsa isa) {
  switch (isa) {
    case KernelIsa::generic:
      return "generic";
    case KernelIsa::avx2:
      return "avx2";
    case KernelIsa::avx512:
      return "avx512";
  }
  return "unknown";
}

KernelIsa parse_kernel_isa(const std::string& name) {
  for (KernelIsa isa : {KernelIsa::generic, KernelIsa::avx2, KernelIsa::avx512}) {
    if (name == to_string(isa)) return isa;
  }
  throw InvalidArgument("unknown kernel set '" + name + "': use generic, avx2 or avx512");
}

namespace {

// The Highway target behind a name: avx512 is HWY_AVX3, avx2 HWY_AVX2, and generic the best
// target below AVX2 this CPU runs (SSE4, or the portable code); in a build whose baseline is
// AVX2 or AVX-512 (-march), which has no such target, the lowest one it has. 0: none.
std::int64_t target_of(KernelIsa isa) {
  const std::vector<std::int64_t> targets = kernels::available_targets();  // best first
  for (std::int64_t target : targets) {
    const bool vector = target == HWY_AVX3 || target == HWY_AVX2;
    if ((isa == KernelIsa::avx512 && target == HWY_AVX3) ||
        (isa == KernelIsa::avx2 && target == HWY_AVX2) || (isa == KernelIsa::generic && !vector)) {
      return target;
    }
  }
  return isa == KernelIsa::generic ? targets.back() : 0;
}

}  // namespace

bool kernel_isa_supported(KernelIsa isa) {
  return target_of(isa) != 0;
}

KernelIsa best_kernel_isa() {
  const std::int64_t best = kernels::best_kernels().target;
  return best == HWY_AVX3   ? KernelIsa::avx512
         : best == HWY_AVX2 ? KernelIsa::avx2
                            : KernelIsa::generic;
}

namespace {

std::atomic<int> g_isa{-1};  // -1: not chosen yet
std::mutex g_isa_mutex;

void require_supported(KernelIsa isa, const std::string& origin) {
  if (!kernel_isa_supported(isa)) {
    throw InvalidArgument(origin + " asks for the " + to_string(isa) +
                          " kernels, which this CPU (or this build) " + "cannot run: use " +
                          to_string(best_kernel_isa()) + " or generic");
  }
}

}  // namespace

KernelIsa kernel_isa() {
  const int chosen = g_isa.load(std::memory_order_acquire);
  if (chosen >= 0) return static_cast<KernelIsa>(chosen);
  std::lock_guard<std::mutex> lock(g_isa_mutex);
  if (g_isa.load() < 0) {
    KernelIsa isa = best_kernel_isa();
    if (const char* env = std::getenv("HANDCENTRIC_KERNELS"); env != nullptr && *env != '\0') {
      try {
        isa = parse_kernel_isa(env);
      } catch (const InvalidArgument& error) {
        throw InvalidArgument(std::string("HANDCENTRIC_KERNELS: ") + error.what());
      }
      require_supported(isa, "HANDCENTRIC_KERNELS=" + std::string(env));
    }
    g_isa.store(static_cast<int>(isa), std::memory_order_release);
  }
  return static_cast<KernelIsa>(g_isa.load());
}

void set_kernel_isa(KernelIsa isa) {
  require_supported(isa, "set_kernel_isa");
  std::lock_guard<std::mutex> lock(g_isa_mutex);
  g_isa.store(static_cast<int>(isa), std::memory_order_release);
}

namespace kernels {

bool trivial_gemm(const Gemm& g) {
  if (g.m <= 0 || g.n <= 0) return true;
  if (g.k > 0) return false;
  for (int j = 0; j < g.n; ++j) {  // the empty product: C = bias 1^T
    for (int i = 0; i < g.m; ++i)
      g.c[i + static_cast<long>(j) * g.ldc] = g.row_bias ? g.row_bias[i] : 0.0f;
  }
  return true;
}

void apply_epilogue(const Gemm& g, int i0, int rows, int j0, int cols, const SiluFunctions& silu) {
  if (g.epilogue == Epilogue::none) return;
  // A block of whole columns that follow each other in C (and in the stored maps) is one run of
  // rows x cols values: one call for all of it instead of one per column of a few rows (an
  // encoder layer of 8 filters made 196k calls of 8 values a step, most of a vector each spent on
  // masked lanes). SiLU acts value by value, so the bits are the same.
  const bool no_maps = g.sigmoid == nullptr && g.activation == nullptr;
  const bool one_run = rows == g.ldc && (no_maps || rows == g.lds);  // then i0 = 0
  const int calls = one_run ? 1 : cols;
  const std::ptrdiff_t length = one_run ? static_cast<std::ptrdiff_t>(rows) * cols : rows;
  for (int j = j0; j < j0 + calls; ++j) {
    float* c = g.c + i0 + static_cast<long>(j) * g.ldc;
    const long s = i0 + static_cast<long>(j) * g.lds;
    if (g.epilogue == Epilogue::silu_derivative) {
      silu.backward(length, g.activation + s, g.sigmoid + s, c);
    } else if (g.sigmoid != nullptr) {
      silu.forward(length, c, g.sigmoid + s, c);
    } else {
      silu.in_place(length, c);
    }
  }
}

const KernelSet& kernels_for(KernelIsa isa) {
  static const auto sets = [] {  // the targets are fixed for the process: looked up once
    std::array<const KernelSet*, 3> table{};
    for (KernelIsa each : {KernelIsa::generic, KernelIsa::avx2, KernelIsa::avx512}) {
      if (const std::int64_t target = target_of(each); target != 0) {
        table[static_cast<std::size_t>(each)] = &kernels_of_target(target);
      }
    }
    return table;
  }();
  return *sets[static_cast<std::size_t>(isa)];
}

const KernelSet& active() {
  return kernels_for(kernel_isa());
}

}  // namespace kernels
}  // namespace handcentric::policy
