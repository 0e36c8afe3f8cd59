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

/// The `Kernel` of gemm.hpp's driver. The register tile is V vectors of rows by NR columns:
/// V NR accumulators plus V vectors of A and one broadcast of B, so with V = 2, NR = 12 uses 27
/// of AVX-512's 32 registers and NR = 6 uses 15 of AVX2's 16. Per k: V loads of A, NR broadcasts
/// of B, V NR FMAs. V = 2 is the product's tile; V = 1 serves products of at most one vector of
/// rows (a layer of 16 filters on AVX-512), which the two-vector tile would compute half of in
/// zero padding. Each entry of C is the same sum in the same order whatever V, so both tiles give
/// the same bits. `Tag` sets the vectors' width: the full one, or half of AVX-512's (8 floats) for
/// products of at most 8 rows (a layer of 8 filters), whose 16-lane tile would spend half of
/// every FMA on padding (and AMD's cores run a 512-bit FMA as two 256-bit halves).
template <int V, class Tag = FloatTag>
struct GemmKernelOf {
  static_assert(V == 1 || V == 2, "one or two vectors of rows");
  /// Floats per vector of this tile.
  static constexpr int kTagLanes = static_cast<int>(hn::MaxLanes(Tag()));
  static constexpr int MR = V * kTagLanes, NR = kRegisters == 32 ? 12 : 6;
  static constexpr int kNarrowLanes = kLanes, kNarrowAccumulators = kRegisters == 32 ? 24 : 12;
  static constexpr int kNarrowGroup = kRegisters == 32 ? 8 : 4;
  /// Whether the narrow products start a shifted, masked head at a vector boundary: only where
  /// a masked load is one instruction; elsewhere the head would go through a buffer every k.
  static constexpr bool kAlignedHeads = kMaskedLoadInstructions;
  template <int N, int W>
  static constexpr auto narrow_block = &NarrowProduct<N, W>;
  static constexpr SiluFunctions kSilu{SiluForward, SiluInPlace, SiluBackward};

  // pack_a<MR> with vector moves: op(A) = A copies V (partial) vectors per k, and adds them to
  // `row_sums` when it is not null (gemm.hpp, blocked_gemm); op(A) = A^T gathers each row
  // panel's k-th column (kTagLanes rows at stride lda) from rows that stay in L1.
  static void pack_a(Op op, const float* a, int lda, int i0, int mc, int p0, int kc, float* out,
                     float* row_sums) {
    // Gather offsets are int32 byte offsets: beyond them, the scalar packing.
    if (op == Op::transpose && static_cast<long>(lda) * kTagLanes >= (1L << 29)) {
      kernels::pack_a<MR>(op, a, lda, i0, mc, p0, kc, out);
      return;
    }
    const Tag d;
    const hn::RebindToSigned<Tag> di;
    const auto row_offsets = hn::Mul(hn::Iota(di, 0), hn::Set(di, lda));
    for (int panel = 0; panel < mc; panel += MR) {
      const int rows = std::min(MR, mc - panel);
      int part[V];  // the rows in each vector of the panel
#pragma GCC unroll 2
      for (int v = 0; v < V; ++v) part[v] = std::clamp(rows - v * kTagLanes, 0, kTagLanes);
      if (op == Op::none && row_sums != nullptr) {
        // The same additions as the narrow product op(A) 1 (whose FMAs by 1 are exact
        // products): each row's sum, in the order of k.
        const float* column = a + (i0 + panel) + static_cast<long>(p0) * lda;
        hn::Vec<Tag> sum[V];
#pragma GCC unroll 2
        for (int v = 0; v < V; ++v) sum[v] = LoadPart(d, row_sums + panel + v * kTagLanes, part[v]);
        for (int p = 0; p < kc; ++p, column += lda) {
#pragma GCC unroll 2
          for (int v = 0; v < V; ++v) {
            const auto x = LoadPart(d, column + v * kTagLanes, part[v]);
            hn::Store(x, d, out + p * MR + v * kTagLanes);
            sum[v] = hn::Add(sum[v], x);
          }
        }
#pragma GCC unroll 2
        for (int v = 0; v < V; ++v) {
          if (part[v] > 0) StorePart(d, sum[v], row_sums + panel + v * kTagLanes, part[v]);
        }
      } else if (op == Op::none) {
        const float* column = a + (i0 + panel) + static_cast<long>(p0) * lda;
        for (int p = 0; p < kc; ++p, column += lda) {
#pragma GCC unroll 2
          for (int v = 0; v < V; ++v)
            hn::Store(LoadPart(d, column + v * kTagLanes, part[v]), d,
                      out + p * MR + v * kTagLanes);
        }
      } else {
        // op(A)(i, p) = a[p + i lda]; a vector without rows gathers the first row again, masked.
        const float* row0 = a + p0 + static_cast<long>(i0 + panel) * lda;
#pragma GCC unroll 2
        for (int v = 0; v < V; ++v) {
          const auto lanes = FirstLanes(d, part[v]);
          const float* rows_v = part[v] > 0 ? row0 + static_cast<long>(v) * kTagLanes * lda : row0;
          for (int p = 0; p < kc; ++p)
            hn::Store(GatherRows(d, rows_v + p, row_offsets, lanes), d,
                      out + p * MR + v * kTagLanes);
        }
      }
      out += static_cast<long>(kc) * MR;
    }
  }

  // The full MR x NR tile of C (gemm.hpp, blocked_gemm).
  template <BLayout layout>
  static void tile(int kc, const float* a, const float* b, int ldb, float* c, int ldc,
                   bool accumulate, const float* bias) {
    hn::Vec<Tag> acc[NR][V];
    multiply(kc, a, acc, [&](int p, int j) HWY_ATTR {
      return layout == BLayout::columns ? b[p + j * static_cast<long>(ldb)]
             : layout == BLayout::rows  ? b[static_cast<long>(p) * ldb + j]
                                        : b[p * NR + j];
    });
    store_tile(acc, c, ldc, accumulate, bias);
  }

  // tile() on a block of op(B) read in place through offsets (gemm.hpp, offset_gemm):
  // op(B)(p, j) = b[p_offsets[p] + j_offsets[j]], the same multiply-adds in the same order.
  static void offset_tile(int kc, const float* a, const float* b, const long* p_offsets,
                          const long* j_offsets, float* c, int ldc, bool accumulate,
                          const float* bias) {
    const float* column[NR];
#pragma GCC unroll 32
    for (int j = 0; j < NR; ++j) column[j] = b + j_offsets[j];
    hn::Vec<Tag> acc[NR][V];
    multiply(kc, a, acc, [&](int p, int j) HWY_ATTR { return column[j][p_offsets[p]]; });
    store_tile(acc, c, ldc, accumulate, bias);
  }

  // acc = the packed A panel (MR x kc) times op(B)'s block, b_at(p, j) = op(B)(p, j) (kc x NR):
  // each entry one chain of multiply-adds from zero, in the order of p.
  template <class BAt>
  static HWY_INLINE void multiply(int kc, const float* a, hn::Vec<Tag> (&acc)[NR][V], BAt&& b_at) {
    const Tag d;
#pragma GCC unroll 32
    for (int j = 0; j < NR; ++j) {
#pragma GCC unroll 2
      for (int v = 0; v < V; ++v) acc[j][v] = hn::Zero(d);
    }
    for (int p = 0; p < kc; ++p) {
      hn::Vec<Tag> a_v[V];
#pragma GCC unroll 2
      for (int v = 0; v < V; ++v) a_v[v] = hn::Load(d, a + v * kTagLanes);
      hwy::Prefetch(a + 8 * MR);
#pragma GCC unroll 32
      for (int j = 0; j < NR; ++j) {
        const auto bj = hn::Set(d, b_at(p, j));
#pragma GCC unroll 2
        for (int v = 0; v < V; ++v) acc[j][v] = hn::MulAdd(a_v[v], bj, acc[j][v]);
      }
      a += MR;
    }
  }

  // C = acc + bias (or + 0), or C += acc: the end of every tile.
  static HWY_INLINE void store_tile(const hn::Vec<Tag> (&acc)[NR][V], float* c, int ldc,
                                    bool accumulate, const float* bias) {
    const Tag d;
    hn::Vec<Tag> add[V];
#pragma GCC unroll 2
    for (int v = 0; v < V; ++v) {
      add[v] = !accumulate && bias != nullptr ? hn::LoadU(d, bias + v * kTagLanes) : hn::Zero(d);
    }
#pragma GCC unroll 32
    for (int j = 0; j < NR; ++j) {
      float* cj = c + static_cast<long>(j) * ldc;
#pragma GCC unroll 2
      for (int v = 0; v < V; ++v) {
        if (accumulate) add[v] = hn::LoadU(d, cj + v * kTagLanes);
        hn::StoreU(hn::Add(acc[j][v], add[v]), d, cj + v * kTagLanes);
      }
    }
  }
};

/// The product's register tile (two vectors of rows) and the one for short products.
using GemmKernel = GemmKernelOf<2>;
using ShortGemmKernel = GemmKernelOf<1>;
/// The tile of at most 8 rows in 8-float vectors: on AVX-512 half of ShortGemmKernel's rows; on
/// AVX2 and narrower targets the same MR as it, and then never chosen (vector_gemm).
using HalfGemmKernel = GemmKernelOf<1, hn::CappedTag<float, 8>>;

}  // namespace handcentric::policy::kernels::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();
