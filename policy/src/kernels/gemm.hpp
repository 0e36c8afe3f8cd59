#pragma once
// Private: the GEMM driver, the loop nests around a target's micro-kernels (gemm-inl.h): packing
// and the blocked nest (the BLIS scheme), the narrow products of n <= 16 columns, and
// vector_gemm that picks one. For the blocked nest, a block of op(A) is copied into panels of MR
// rows, each panel k-major (panel[k * MR + i]); a block of op(B) into panels of NR columns
// (panel[k * NR + j]). Rows and columns past the matrix are zero, so the micro-kernel always runs
// on full MR x NR tiles.
// These templates are defined outside Highway's per-target regions, so they compile for the
// build's baseline target whatever kernel they are instantiated with, and call the kernel's
// functions: packing is O(mk + kn) against the O(mnk) products and does not need vector code.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <new>
#include <utility>
#include <vector>

#include "kernel_set.hpp"

namespace handcentric::policy::kernels {

/// Panels of MR rows of op(A)(i0 : i0 + mc, p0 : p0 + kc) into `out` (ceil(mc / MR) * kc * MR
/// floats).
template <int MR>
void pack_a(Op op, const float* a, int lda, int i0, int mc, int p0, int kc, float* out) {
  for (int panel = 0; panel < mc; panel += MR) {
    const int rows = std::min(MR, mc - panel);
    if (op == Op::none) {
      for (int p = 0; p < kc; ++p) {
        const float* column = a + (i0 + panel) + static_cast<long>(p0 + p) * lda;
        float* dst = out + p * MR;
        for (int i = 0; i < rows; ++i) dst[i] = column[i];
        for (int i = rows; i < MR; ++i) dst[i] = 0.0f;
      }
    } else {
      for (int i = 0; i < MR; ++i) {
        if (i < rows) {
          const float* row = a + p0 + static_cast<long>(i0 + panel + i) * lda;  // contiguous in p
          for (int p = 0; p < kc; ++p) out[p * MR + i] = row[p];
        } else {
          for (int p = 0; p < kc; ++p) out[p * MR + i] = 0.0f;
        }
      }
    }
    out += static_cast<long>(kc) * MR;
  }
}

/// Panels of NR columns of op(B)(p0 : p0 + kc, j0 : j0 + nc) into `out` (ceil(nc / NR) * kc * NR
/// floats): the panels of NR rows of op(B)^T, whose op is the other one.
template <int NR>
void pack_b(Op op, const float* b, int ldb, int p0, int kc, int j0, int nc, float* out) {
  pack_a<NR>(op == Op::none ? Op::transpose : Op::none, b, ldb, j0, nc, p0, kc, out);
}

/// A float buffer on a 64-byte boundary (a cache line; the micro-kernels load it aligned).
class AlignedBuffer {
 public:
  float* data() { return data_.get(); }
  /// Grows (contents lost) to at least `count` floats.
  void resize(std::size_t count) {
    if (count <= size_) return;
    const std::size_t bytes = (count * sizeof(float) + 63) / 64 * 64;
    data_.reset(static_cast<float*>(::operator new[](bytes, std::align_val_t{64})));
    size_ = count;
  }

 private:
  struct Free {
    void operator()(float* p) const { ::operator delete[](p, std::align_val_t{64}); }
  };
  std::unique_ptr<float[], Free> data_;
  std::size_t size_ = 0;
};

/// Buffers reused across calls on one thread (no allocation once they are large enough).
struct PackBuffers {
  AlignedBuffer a, b;
  static PackBuffers& local() {
    thread_local PackBuffers buffers;
    return buffers;
  }
};

/// How a micro-kernel reads its k x NR block of op(B): `packed` (panel[p * NR + j], from
/// pack_b), or in place, `rows` (op(B) = B^T: b[p * ldb + j]) or `columns` (op(B) = B:
/// b[p + j * ldb]).
enum class BLayout { packed, rows, columns };

/// The block sizes of the blocked nest, for the caches they assume (the smallest of the x86 cores
/// the kernels target: 32 KB L1d, 1 MB L2 per core):
/// - KC = 256: a micro-kernel streams an MR x KC panel of packed op(A) against a KC x NR block of
///   op(B) that every row panel reuses; both together (at most 32 x 256 + 256 x 12 floats, 44 KB
///   at MR = 32, NR = 12; 22 KB at 16 x 6) fit the L1d with the tile of C, or nearly: the A panel
///   is read once per tile, in order, which the prefetchers cover.
/// - MC = 256: the packed MC x KC block of op(A), 256 KB, stays in L2 while the nest walks the
///   columns of C.
/// - NC = 384: the KC x NC block of op(B) read in place, 384 KB, stays in L2 beside it
///   (640 KB of the 1 MB).
struct Blocking {
  static constexpr std::size_t kL1Bytes = 32 * 1024, kL2Bytes = 1024 * 1024;
  static constexpr int KC = kProductKBlock, MC = 256, NC = 384;
  static_assert((MC + NC) * KC * sizeof(float) <= kL2Bytes, "the A block and the B block share L2");
};

/// op(B) as a matrix in memory (Gemm::b, ldb, op_b), for blocked_nest: a last partial panel
/// packed by pack_b (`pack`, into `packed`, zero padded), a full one read in place by the
/// kernel's tile.
struct MatrixB {
  const Gemm& g;
  template <int NR>
  void pack(int p0, int kc, int j, int cols, float* packed) const {
    pack_b<NR>(g.op_b, g.b, g.ldb, p0, kc, j, cols, packed);
  }
  template <typename Kernel>
  void tile(int kc, const float* a_panel, int p0, long j, int cols, const float* packed, float* c,
            int ldc, bool accumulate, const float* bias) const {
    if (cols < Kernel::NR) {
      Kernel::template tile<BLayout::packed>(kc, a_panel, packed, Kernel::NR, c, ldc, accumulate,
                                             bias);
    } else if (g.op_b == Op::none) {
      Kernel::template tile<BLayout::columns>(kc, a_panel, g.b + p0 + j * g.ldb, g.ldb, c, ldc,
                                              accumulate, bias);
    } else {
      Kernel::template tile<BLayout::rows>(kc, a_panel, g.b + j + static_cast<long>(p0) * g.ldb,
                                           g.ldb, c, ldc, accumulate, bias);
    }
  }
};

/// op(B) read through offsets (OffsetGemm), for blocked_nest: op(B)(p, j) =
/// b[row_offsets[p] + column_offsets[j]], every panel in place; a partial one repeats its last
/// column into the tile's spare columns (each column of C is its own sum, and the edge tile keeps
/// only the valid ones), so nothing is packed.
struct OffsetB {
  const float* b;
  const long* row_offsets;
  const long* column_offsets;
  template <int NR>
  void pack(int, int, int, int, float*) const {}
  template <typename Kernel>
  void tile(int kc, const float* a_panel, int p0, long j, int cols, const float*, float* c, int ldc,
            bool accumulate, const float* bias) const {
    const long* columns = column_offsets + j;
    long edge[Kernel::NR];
    if (cols < Kernel::NR) {
      for (int jj = 0; jj < Kernel::NR; ++jj) edge[jj] = columns[std::min(jj, cols - 1)];
      columns = edge;
    }
    Kernel::offset_tile(kc, a_panel, b, row_offsets + p0, columns, c, ldc, accumulate, bias);
  }
};

/// The blocked loop nest shared by the targets (the BLIS order: columns of C, then k, then rows).
/// A block of MC x KC of op(A) is packed (it stays in L2 and streams through the micro-kernel);
/// op(B) is read in place (`source`: MatrixB or OffsetB), NR columns at a time (a k x NR block is
/// reused from L1 by every row panel); a last partial panel as the source says.
/// Kernel::kSilu (SiluFunctions) applies Gemm::epilogue to each finished block.
/// Kernel::pack_a has pack_a<MR>'s contract (it may be a faster vector version) and one more
/// argument, `row_sums` (null, or with op(A) = A the mc sums of the block's rows, to which it adds
/// the block's kc entries of each row in order).
/// Kernel::tile<BLayout>(kc, a_panel, b, ldb, c, ldc, accumulate, bias) writes a full MR x NR
/// tile of C: C = A B (+ bias, an MR-float pointer or null) or, when accumulate, C += A B;
/// Kernel::offset_tile the same from op(B) read through offsets.
/// The first k block writes C (plus the bias), later ones add to it.
template <typename Kernel, typename Source>
void blocked_nest(const Gemm& g, const Source& source) {
  constexpr int MR = Kernel::MR, NR = Kernel::NR;
  constexpr int KC = Blocking::KC, MC = Blocking::MC, NC = Blocking::NC;
  static_assert(static_cast<std::size_t>(KC) * (MR + NR) * sizeof(float) <= 2 * Blocking::kL1Bytes,
                "an A panel and a B block of one k block (nearly) fit L1d");
  PackBuffers& buffers = PackBuffers::local();
  buffers.a.resize(static_cast<std::size_t>((MC + MR - 1) / MR * MR) * KC);
  buffers.b.resize(static_cast<std::size_t>(NR) * KC);
  alignas(64) float tile[MR * NR];
  alignas(64) float bias_tile[MR];
  // The row sums of A, added up by the packing of the first column block (which packs every
  // (i0, p0) block once, p0 ascending).
  if (g.a_row_sums != nullptr && !g.accumulate) std::fill(g.a_row_sums, g.a_row_sums + g.m, 0.0f);
  for (int j0 = 0; j0 < g.n; j0 += NC) {
    const int nc = std::min(NC, g.n - j0);
    const int full = nc / NR * NR;  // columns in full panels, read in place
    for (int p0 = 0; p0 < g.k; p0 += KC) {
      const int kc = std::min(KC, g.k - p0);
      const bool accumulate = p0 > 0 || g.accumulate;
      if (full < nc) {
        source.template pack<NR>(p0, kc, j0 + full, nc - full, buffers.b.data());
      }
      for (int i0 = 0; i0 < g.m; i0 += MC) {
        const int mc = std::min(MC, g.m - i0);
        float* row_sums = j0 == 0 && g.a_row_sums != nullptr ? g.a_row_sums + i0 : nullptr;
        Kernel::pack_a(g.op_a, g.a, g.lda, i0, mc, p0, kc, buffers.a.data(), row_sums);
        for (int jr = 0; jr < nc; jr += NR) {
          const int cols = std::min(NR, nc - jr);
          const long j = j0 + jr;
          for (int ir = 0; ir < mc; ir += MR) {
            const int rows = std::min(MR, mc - ir);
            const float* a_panel = buffers.a.data() + static_cast<long>(ir / MR) * kc * MR;
            const float* bias = nullptr;
            if (!accumulate && g.row_bias != nullptr) {
              bias = g.row_bias + i0 + ir;
              if (rows < MR) {
                std::fill(bias_tile, bias_tile + MR, 0.0f);
                std::copy(bias, bias + rows, bias_tile);
                bias = bias_tile;
              }
            }
            float* c = g.c + (i0 + ir) + j * g.ldc;
            float* target = c;
            int ld_target = g.ldc;
            if (rows < MR ||
                cols < NR) {  // an edge tile: computed in `tile`, the valid part copied
              target = tile;
              ld_target = MR;
              if (accumulate) {
                for (int jj = 0; jj < cols; ++jj)
                  std::copy(c + jj * g.ldc, c + jj * g.ldc + rows, tile + jj * MR);
              }
            }
            source.template tile<Kernel>(kc, a_panel, p0, j, cols, buffers.b.data(), target,
                                         ld_target, accumulate, bias);
            if (target == tile) {
              for (int jj = 0; jj < cols; ++jj)
                std::copy(tile + jj * MR, tile + jj * MR + rows, c + jj * g.ldc);
            }
          }
          if (p0 + kc == g.k) {  // this mc x cols block of C is complete and still in L1
            apply_epilogue(g, i0, mc, static_cast<int>(j), cols, Kernel::kSilu);
          }
        }
      }
    }
  }
}

/// The blocked product of a matrix op(B).
template <typename Kernel>
void blocked_gemm(const Gemm& g) {
  blocked_nest<Kernel>(g, MatrixB{g});
}

// Narrow products (n <= kNarrowMax columns: batch-1 sampling is n = 1, the C8 average n = 8).
// Packing A would cost as much as the product, so A is streamed in place, column by column, and
// each loaded vector of A is used for all N columns of C:
//   C(rows, 0:N) = A(rows, 0:k) op(B)(0:k, 0:N) (+ bias), with N x V accumulators held over the
// whole k loop, op(B)(p, j) = b[p * b_step + j * b_stride].
// When every column of A starts `shift` floats past a boundary of one vector's width (Eigen
// aligns its heap to 16 bytes only), the vectors start `shift` lanes early so that no load splits
// a cache line: the first vector masks off its first `shift` lanes and the last one the lanes
// past the end (masked lanes are neither read nor written). Needs shift + rows <= lanes V.
// Kernel provides kNarrowLanes (floats per vector), kNarrowAccumulators (N V <= it),
// kNarrowGroup (columns per pass), kAlignedHeads (whether to shift the heads at all) and
//   template <int N, int V>
//   narrow_block(shift, rows, k, a, lda, b, b_step, b_stride, bias, c, ldc).
template <typename Kernel, int N, int... V>
void narrow_rows(int vectors, int shift, int rows, int k, const float* a, long lda, const float* b,
                 long b_step, long b_stride, const float* bias, float* c, long ldc,
                 std::integer_sequence<int, V...>) {
  ((vectors == V + 1 ? Kernel::template narrow_block<N, V + 1>(shift, rows, k, a, lda, b, b_step,
                                                               b_stride, bias, c, ldc)
                     : void()),
   ...);
}

// Columns j0 .. j0 + N of C, in blocks of rows that fill the accumulators.
template <typename Kernel, int N>
void narrow_columns(const Gemm& g, int j0) {
  constexpr int kLanes = Kernel::kNarrowLanes, kVectors = Kernel::kNarrowAccumulators / N;
  const long b_step = g.op_b == Op::none ? 1 : g.ldb, b_stride = g.op_b == Op::none ? g.ldb : 1;
  // Columns share their offset from a vector boundary when lda is a multiple of the lanes.
  const auto address = reinterpret_cast<std::uintptr_t>(g.a);
  const int shift = (Kernel::kAlignedHeads && g.lda % kLanes == 0 && address % 4 == 0)
                        ? static_cast<int>(address % (4 * kLanes) / 4)
                        : 0;
  const int block_rows = kLanes * kVectors - shift;
  for (int i0 = 0; i0 < g.m; i0 += block_rows) {
    const int rows = std::min(block_rows, g.m - i0);
    const int block_shift = i0 == 0 ? shift : 0;  // later blocks start on a boundary
    narrow_rows<Kernel, N>((block_shift + rows + kLanes - 1) / kLanes, block_shift, rows, g.k,
                           g.a + i0, g.lda, g.b + j0 * b_stride, b_step, b_stride,
                           g.row_bias ? g.row_bias + i0 : nullptr,
                           g.c + i0 + static_cast<long>(j0) * g.ldc, g.ldc,
                           std::make_integer_sequence<int, kVectors>{});
  }
}

template <typename Kernel, int... N>
void narrow_dispatch(const Gemm& g, int j0, int columns, std::integer_sequence<int, N...>) {
  ((columns == N + 1 ? narrow_columns<Kernel, N + 1>(g, j0) : void()), ...);
}

// op(A) = A, n <= kNarrowMax: groups of kNarrowGroup columns.
template <typename Kernel>
void narrow_gemm(const Gemm& g) {
  constexpr int kGroup = Kernel::kNarrowGroup;
  for (int j0 = 0; j0 < g.n; j0 += kGroup) {
    narrow_dispatch<Kernel>(g, j0, std::min(kGroup, g.n - j0),
                            std::make_integer_sequence<int, kGroup>{});
  }
}

/// Gemm::a_row_sums where the blocked nest does not add them up while packing: a pass of its own,
/// in the same order.
inline void sum_rows_of_a(const Gemm& g) {
  if (!g.accumulate) std::fill(g.a_row_sums, g.a_row_sums + g.m, 0.0f);
  for (int p = 0; p < g.k; ++p) {
    for (int i = 0; i < g.m; ++i) {
      g.a_row_sums[i] += g.op_a == Op::none ? g.a[i + static_cast<long>(p) * g.lda]
                                            : g.a[p + static_cast<long>(i) * g.lda];
    }
  }
}

/// KernelSet::gemm of a vector set: the degenerate shapes, the narrow products, or the blocked
/// product, then the epilogue where the blocked nest has not applied it. The blocked product runs
/// on ShortKernel, a tile of fewer rows (ShortKernel::MR < Kernel::MR), when op(A) has no more
/// rows than it: Kernel's tile would spend the rest of its rows on zero padding; and on
/// HalfKernel, narrower still, when it has fewer rows than ShortKernel and op(A) fits it. Each
/// entry of C is the same sum in the same order on every tile, so the choice changes no bit.
template <typename Kernel, typename ShortKernel, typename HalfKernel = ShortKernel>
void vector_gemm(const Gemm& g) {
  static_assert(ShortKernel::MR < Kernel::MR, "the short tile has fewer rows");
  static_assert(HalfKernel::MR <= ShortKernel::MR, "the half tile has no more rows");
  if (g.a_row_sums != nullptr && g.m > 0 && (g.n <= kNarrowMax || g.k <= 0 || g.op_a != Op::none)) {
    sum_rows_of_a(g);  // the blocked nest's packing does not run on op(A) = A
    Gemm rest = g;
    rest.a_row_sums = nullptr;
    vector_gemm<Kernel, ShortKernel, HalfKernel>(rest);
  } else if (g.accumulate && (g.m <= 0 || g.n <= 0 || g.k <= 0)) {
    // nothing to add
  } else if (trivial_gemm(g)) {
    apply_epilogue(g, 0, g.m, 0, g.n, Kernel::kSilu);
  } else if (g.n <= kNarrowMax && g.op_a == Op::none && !g.accumulate) {
    narrow_gemm<Kernel>(g);
    apply_epilogue(g, 0, g.m, 0, g.n, Kernel::kSilu);
  } else if (HalfKernel::MR < ShortKernel::MR && g.m <= HalfKernel::MR) {
    blocked_gemm<HalfKernel>(g);
  } else if (g.m <= ShortKernel::MR) {
    blocked_gemm<ShortKernel>(g);
  } else {
    blocked_gemm<Kernel>(g);
  }
}

/// KernelSet::offset_gemm of a vector set: the blocked nest reading op(B) through the offsets
/// wherever vector_gemm would run the blocked nest on it (n > kNarrowMax, row sums only with
/// op(A) = A); elsewhere (the narrow and degenerate products) op(B) gathered into a matrix for
/// vector_gemm. Either way C has the bits vector_gemm gives on that matrix.
template <typename Kernel, typename ShortKernel, typename HalfKernel = ShortKernel>
void vector_offset_gemm(const OffsetGemm& problem) {
  const Gemm& g = problem.product;
  if (g.m > 0 && g.n > kNarrowMax && g.k > 0 && (g.a_row_sums == nullptr || g.op_a == Op::none)) {
    const OffsetB source{g.b, problem.b_row_offsets, problem.b_column_offsets};
    if (HalfKernel::MR < ShortKernel::MR && g.m <= HalfKernel::MR) {
      blocked_nest<HalfKernel>(g, source);
    } else if (g.m <= ShortKernel::MR) {
      blocked_nest<ShortKernel>(g, source);
    } else {
      blocked_nest<Kernel>(g, source);
    }
    return;
  }
  const int k = std::max(g.k, 0), n = std::max(g.n, 0);
  std::vector<float> matrix(static_cast<std::size_t>(k) * n);
  for (int j = 0; j < n; ++j) {
    for (int p = 0; p < k; ++p) {
      matrix[p + static_cast<std::size_t>(j) * k] =
          g.b[problem.b_row_offsets[p] + problem.b_column_offsets[j]];
    }
  }
  Gemm gathered = g;
  gathered.op_b = Op::none;
  gathered.b = matrix.data();
  gathered.ldb = std::max(k, 1);
  vector_gemm<Kernel, ShortKernel, HalfKernel>(gathered);
}

}  // namespace handcentric::policy::kernels
