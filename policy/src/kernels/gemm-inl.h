// Private, per target: the micro-kernels the GEMM driver (gemm.hpp) runs, as its `Kernel`:
// the register tile of the blocked nest, the narrow products, and packing with vector moves.

#include <algorithm>

#include <hwy/cache_control.h>
#include <hwy/highway.h>

#include "kernels/gemm.hpp"
#include "kernels/kernel_set.hpp"

HWY_BEFORE_NAMESPACE();
namespace handcentric::policy::kernels::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

using FloatTag = hn::ScalableTag<float>;
/// Floats per vector.
constexpr int kLanes = static_cast<int>(hn::MaxLanes(FloatTag()));
/// Vector registers the tiles may fill (AVX-512 has 32, AVX2 16; the portable targets keep
/// their "registers" in memory, where the count only sets the tile's shape).
constexpr int kRegisters = HWY_TARGET == HWY_AVX3 || HWY_TARGET == HWY_AVX3_DL ? 32 : 16;

// One narrow product C(rows, 0:N) = A(rows, 0:k) op(B)(0:k, 0:N) (+ bias) with N x V accumulators:
// the contract of gemm.hpp's narrow loop nest ("Narrow products"). The first vector starts
// `shift` lanes before the data and the last one ends inside its vector: both are masked.
template <int N, int V>
void NarrowProduct(int shift, int rows, int k, const float* a, long lda, const float* b,
                   long b_step, long b_stride, const float* bias, float* c, long ldc) {
  const FloatTag d;
  const int lanes = shift + rows;  // in kLanes (V - 1) + 1 .. kLanes V
  const auto head = LanesBetween(d, shift, V == 1 ? lanes : kLanes);
  const auto tail = LanesBetween(d, V == 1 ? shift : 0, lanes - kLanes * (V - 1));
  a -= shift;
  c -= shift;
  if (bias != nullptr) bias -= shift;
  const auto load = [&](const float* p, int v) HWY_ATTR {
    return v == 0 ? LoadLanes(d, head, p) : v + 1 == V ? LoadLanes(d, tail, p) : hn::LoadU(d, p);
  };
  hn::Vec<FloatTag> acc[N][V];
#pragma GCC unroll 32
  for (int v = 0; v < V; ++v) {
    const auto start = bias != nullptr ? load(bias + kLanes * v, v) : hn::Zero(d);
#pragma GCC unroll 16
    for (int j = 0; j < N; ++j) acc[j][v] = start;
  }
  for (int p = 0; p < k; ++p) {
    const float* column = a + p * lda;
    const float* b_row = b + p * b_step;
    // No software prefetch: measured (n = 1), prefetching 2, 4 or 8 columns ahead changed nothing.
#pragma GCC unroll 32
    for (int v = 0; v < V; ++v) {
      const auto a_v = load(column + kLanes * v, v);
#pragma GCC unroll 16
      for (int j = 0; j < N; ++j)
        acc[j][v] = hn::MulAdd(a_v, hn::Set(d, b_row[j * b_stride]), acc[j][v]);
    }
  }
#pragma GCC unroll 16
  for (int j = 0; j < N; ++j) {
    float* cj = c + j * ldc;
#pragma GCC unroll 32
    for (int v = 0; v < V; ++v) {
      if (v == 0) {
        StoreLanes(d, head, acc[j][0], cj);
      } else if (v + 1 == V) {
        StoreLanes(d, tail, acc[j][v], cj + kLanes * v);
      } else {
        hn::StoreU(acc[j][v], d, cj + kLanes * v);
      }
    }
  }
}

/// The `Kernel` of gemm.hpp's driver. The register tile is two vectors of rows by NR columns:
/// 2 NR accumulators plus two vectors of A and one broadcast of B, so NR = 12 uses 27 of
/// AVX-512's 32 registers and NR = 6 uses 15 of AVX2's 16. Per k: 2 loads of A, NR broadcasts of
/// B, 2 NR FMAs.
struct GemmKernel {
  static constexpr int MR = 2 * kLanes, NR = kRegisters == 32 ? 12 : 6;
  static constexpr int kNarrowLanes = kLanes, kNarrowAccumulators = kRegisters == 32 ? 24 : 12;
  static constexpr int kNarrowGroup = kRegisters == 32 ? 8 : 4;
  /// Whether the narrow products start a shifted, masked head at a vector boundary: only where
  /// a masked load is one instruction; elsewhere the head would go through a buffer every k.
  static constexpr bool kAlignedHeads = kMaskedLoadInstructions;
  template <int N, int V>
  static constexpr auto narrow_block = &NarrowProduct<N, V>;
  static constexpr SiluFunctions kSilu{SiluForward, SiluInPlace, SiluBackward};

  // pack_a<MR> with vector moves: op(A) = A copies two (partial) vectors per k; op(A) = A^T
  // gathers each row panel's k-th column (kLanes rows at stride lda) from rows that stay in L1.
  static void pack_a(Op op, const float* a, int lda, int i0, int mc, int p0, int kc, float* out) {
    // Gather offsets are int32 byte offsets: beyond them, the scalar packing.
    if (op == Op::transpose && static_cast<long>(lda) * kLanes >= (1L << 29)) {
      kernels::pack_a<MR>(op, a, lda, i0, mc, p0, kc, out);
      return;
    }
    const FloatTag d;
    const hn::RebindToSigned<FloatTag> di;
    const auto row_offsets = hn::Mul(hn::Iota(di, 0), hn::Set(di, lda));
    for (int panel = 0; panel < mc; panel += MR) {
      const int rows = std::min(MR, mc - panel);
      const int rows0 = std::min(rows, kLanes), rows1 = rows - rows0;  // in each half of the panel
      if (op == Op::none) {
        const float* column = a + (i0 + panel) + static_cast<long>(p0) * lda;
        for (int p = 0; p < kc; ++p, column += lda) {
          hn::Store(LoadPart(d, column, rows0), d, out + p * MR);
          hn::Store(LoadPart(d, column + kLanes, rows1), d, out + p * MR + kLanes);
        }
      } else {
        const auto lanes0 = FirstLanes(d, rows0), lanes1 = FirstLanes(d, rows1);
        // op(A)(i, p) = a[p + i lda]
        const float* row0 = a + p0 + static_cast<long>(i0 + panel) * lda;
        const float* row1 = rows1 > 0 ? row0 + static_cast<long>(kLanes) * lda : row0;
        for (int p = 0; p < kc; ++p) {
          hn::Store(GatherRows(d, row0 + p, row_offsets, lanes0), d, out + p * MR);
          hn::Store(GatherRows(d, row1 + p, row_offsets, lanes1), d, out + p * MR + kLanes);
        }
      }
      out += static_cast<long>(kc) * MR;
    }
  }

  // The full MR x NR tile of C (gemm.hpp, blocked_gemm).
  template <BLayout layout>
  static void tile(int kc, const float* a, const float* b, int ldb, float* c, int ldc,
                   bool accumulate, const float* bias) {
    const FloatTag d;
    hn::Vec<FloatTag> acc[NR][2];
#pragma GCC unroll 32
    for (int j = 0; j < NR; ++j) acc[j][0] = acc[j][1] = hn::Zero(d);
    for (int p = 0; p < kc; ++p) {
      const auto a0 = hn::Load(d, a), a1 = hn::Load(d, a + kLanes);
      hwy::Prefetch(a + 8 * MR);
#pragma GCC unroll 32
      for (int j = 0; j < NR; ++j) {
        const auto bj =
            hn::Set(d, layout == BLayout::columns ? b[j * static_cast<long>(ldb)] : b[j]);
        acc[j][0] = hn::MulAdd(a0, bj, acc[j][0]);
        acc[j][1] = hn::MulAdd(a1, bj, acc[j][1]);
      }
      a += MR;
      b += layout == BLayout::packed ? NR : layout == BLayout::rows ? ldb : 1;
    }
    auto add0 = hn::Zero(d), add1 = hn::Zero(d);
    if (!accumulate && bias != nullptr) {
      add0 = hn::LoadU(d, bias);
      add1 = hn::LoadU(d, bias + kLanes);
    }
#pragma GCC unroll 32
    for (int j = 0; j < NR; ++j) {
      float* cj = c + static_cast<long>(j) * ldc;
      if (accumulate) {
        add0 = hn::LoadU(d, cj);
        add1 = hn::LoadU(d, cj + kLanes);
      }
      hn::StoreU(hn::Add(acc[j][0], add0), d, cj);
      hn::StoreU(hn::Add(acc[j][1], add1), d, cj + kLanes);
    }
  }
};

}  // namespace handcentric::policy::kernels::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();
