// Private, per target: col2im and row2im (kernel_set.hpp, ConvPatches), which add a patch
// matrix's gradient back onto the pixels its entries were read from (the input gradient of a
// convolution), and the first layer's forward product and weight gradient with the pixels in the
// lanes (PixelConv, PixelConvGradient).
// The other forward products read their patches in place (OffsetGemm), so nothing writes a patch
// matrix; those products are the GEMM driver's.

#include <algorithm>
#include <cstddef>
#include <vector>

#include <hwy/aligned_allocator.h>
#include <hwy/highway.h>

#include "kernels/kernel_set.hpp"

HWY_BEFORE_NAMESPACE();
namespace handcentric::policy::kernels::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

/// body(patch_offset, pixel) for every in-image run of one output pixel's patch: `count`
/// consecutive patch entries that read `count` consecutive floats of the image (a row of the
/// window when the channels and columns are dense, channel_stride 1 or a single channel, and
/// column_stride channels), or one entry each when they are not (then pixel is the address of that
/// one float). Entries whose pixel is in the padding are passed to `padding(patch_offset, count)`.
template <class Run, class Pad>
HWY_INLINE void ForEachPatchRun(const ConvPatches& g, long sample, int oy, int ox, Run&& run,
                                Pad&& padding) {
  const int c = g.channels;
  // One channel needs no channel stride: a depth image (channels, height, width) is dense too.
  const bool dense = (c == 1 || g.channel_stride == 1) && g.column_stride == c;
  const int x0 = ox * g.stride - g.padding, y0 = oy * g.stride - g.padding;
  // The window's columns inside the image: kx in [kx_begin, kx_end).
  const int kx_begin = std::max(0, -x0), kx_end = std::min(g.kernel, g.width - x0);
  for (int ky = 0; ky < g.kernel; ++ky) {
    const int row_start = ky * g.kernel * c;
    const int iy = y0 + ky;
    if (iy < 0 || iy >= g.height || kx_begin >= kx_end) {
      padding(row_start, g.kernel * c);
      continue;
    }
    if (kx_begin > 0) padding(row_start, kx_begin * c);
    if (kx_end < g.kernel) padding(row_start + kx_end * c, (g.kernel - kx_end) * c);
    const long first =
        sample + iy * g.row_stride + static_cast<long>(x0 + kx_begin) * g.column_stride;
    if (dense) {
      run(row_start + kx_begin * c, first, (kx_end - kx_begin) * c);
      continue;
    }
    for (int kx = kx_begin; kx < kx_end; ++kx) {
      const long column = first + static_cast<long>(kx - kx_begin) * g.column_stride;
      for (int ch = 0; ch < c; ++ch)
        run(row_start + kx * c + ch, column + ch * g.channel_stride, 1);
    }
  }
}

inline void Col2im(const ConvPatches& g, const float* patches, float* image) {
  const hn::ScalableTag<float> d;
  const long k = static_cast<long>(g.kernel) * g.kernel * g.channels;
  const float* in = patches;
  for (int b = 0; b < g.batch; ++b) {
    const long sample = b * g.sample_stride;
    for (int oy = 0; oy < g.out_height; ++oy) {
      for (int ox = 0; ox < g.out_width; ++ox, in += k) {
        ForEachPatchRun(
            g, sample, oy, ox,
            [&](int at, long pixel, int count) HWY_ATTR {
              if (count == 1) {
                image[pixel] += in[at];
                return;
              }
              ForEachVector(d, count, [&](std::ptrdiff_t i, std::size_t n) HWY_ATTR {
                const auto sum =
                    hn::Add(LoadPart(d, image + pixel + i, n), LoadPart(d, in + at + i, n));
                StorePart(d, sum, image + pixel + i, n);
              });
            },
            [](int, int) {});
      }
    }
  }
}

/// For every patch entry p = (ky, kx, c) and every row of output pixels (b, oy): the output
/// columns whose input column ox stride - padding + kx lies in the image, [ox_begin, ox_end), go
/// to run(p, j, pixel, count): `count` pixels from output pixel j (the index (b, oy, ox) of
/// ConvPatches) read image[pixel + i stride column_stride], i < count; the others, in the padding,
/// go to padding(p, j, count).
template <class Run, class Pad>
HWY_INLINE void ForEachPatchLine(const ConvPatches& g, Run&& run, Pad&& padding) {
  const int s = g.stride;
  for (int ky = 0; ky < g.kernel; ++ky) {
    for (int kx = 0; kx < g.kernel; ++kx) {
      const int before = g.padding - kx, last = g.width - 1 + g.padding - kx;
      const int ox_begin = std::min(g.out_width, before > 0 ? (before + s - 1) / s : 0);
      const int ox_end = std::max(ox_begin, last < 0 ? 0 : std::min(g.out_width, last / s + 1));
      const long column = static_cast<long>(ox_begin * s - g.padding + kx) * g.column_stride;
      for (int c = 0; c < g.channels; ++c) {
        const long p = (static_cast<long>(ky) * g.kernel + kx) * g.channels + c;
        for (int b = 0; b < g.batch; ++b) {
          for (int oy = 0; oy < g.out_height; ++oy) {
            const long j = (static_cast<long>(b) * g.out_height + oy) * g.out_width;
            const int iy = oy * s - g.padding + ky;
            if (iy < 0 || iy >= g.height) {
              padding(p, j, g.out_width);
              continue;
            }
            padding(p, j, ox_begin);
            run(p, j + ox_begin,
                b * g.sample_stride + c * g.channel_stride + iy * g.row_stride + column,
                ox_end - ox_begin);
            padding(p, j + ox_end, g.out_width - ox_end);
          }
        }
      }
    }
  }
}

#if HWY_TARGET != HWY_AVX3 && HWY_TARGET != HWY_AVX3_DL
// Only AVX-512 has vectors twice as wide as 8 filters: on AVX2 the offset product's tile already
// fills its vectors, and the portable targets keep theirs in memory. There pixel_conv is the
// offset product itself (its bits by definition), on every output pixel's offset; the pixel tile
// and its transposition also cost each of those targets seconds to half a minute of compilation
// under the sanitizers.

/// The offset of every pixel of `rows` rows of `width` consecutive floats, from each row's first.
inline std::vector<long> EveryPixelOffset(int rows, int width, const long* row_offsets) {
  const long n = static_cast<long>(rows) * width;
  std::vector<long> pixels(static_cast<std::size_t>(std::max(n, 1L)));
  for (long r = 0; r < rows; ++r) {
    for (int x = 0; x < width; ++x) pixels[r * width + x] = row_offsets[r * width] + x;
  }
  return pixels;
}

inline void PixelConvForward(const PixelConv& g) {
  constexpr int F = kPixelConvFilters;
  const long n = static_cast<long>(g.rows) * g.width;
  const std::vector<long> pixels = EveryPixelOffset(g.rows, g.width, g.pixel_offsets);
  Gemm product{Op::none, Op::none, F, static_cast<int>(n), g.k, g.weights, F, g.input, g.k,
               g.bias,   g.c,      F};
  product.epilogue = Epilogue::silu;
  product.sigmoid = g.sigmoid;
  product.lds = F;
  vector_offset_gemm<GemmKernel, ShortGemmKernel, HalfGemmKernel>(
      {product, g.patch_offsets, pixels.data()});
}

/// dW = delta P^T and db = delta 1 as the offset product with the row sums of its A (the bits
/// it has always had on these targets).
inline void PixelConvWeights(const PixelConvGradient& g) {
  constexpr int F = kPixelConvFilters;
  const long n = static_cast<long>(g.rows) * g.width;
  const std::vector<long> pixels = EveryPixelOffset(g.rows, g.width, g.pixel_offsets);
  Gemm product{
      Op::none, Op::none,    F, g.k, static_cast<int>(n), g.delta, F, g.input, static_cast<int>(n),
      nullptr,  g.d_weights, F};
  product.a_row_sums = g.d_bias;
  vector_offset_gemm<GemmKernel, ShortGemmKernel, HalfGemmKernel>(
      {product, pixels.data(), g.patch_offsets});
}
#else
/// Rotates the element indices of kPixelConvFilters vectors, read as one array of F L floats
/// (L lanes, F = kPixelConvFilters, both powers of two), right by kRounds bits: one round of
/// ConcatEven and ConcatOdd over the vectors' pairs (the even elements of the whole array, then
/// the odd ones) rotates every index right by one bit.
template <int kRounds, class D>
HWY_INLINE void RotateElementIndices(D d, hn::Vec<D> (&v)[kPixelConvFilters]) {
  constexpr int kHalf = kPixelConvFilters / 2;
#pragma GCC unroll 4
  for (int round = 0; round < kRounds; ++round) {
    hn::Vec<D> next[kPixelConvFilters];
#pragma GCC unroll 4
    for (int t = 0; t < kHalf; ++t) {
      next[t] = hn::ConcatEven(d, v[2 * t + 1], v[2 * t]);
      next[kHalf + t] = hn::ConcatOdd(d, v[2 * t + 1], v[2 * t]);
    }
#pragma GCC unroll 8
    for (int f = 0; f < kPixelConvFilters; ++f) v[f] = next[f];
  }
}

/// Transposes kPixelConvFilters vectors in place: v[f] holds filter f of the vector's pixels
/// (lane i: pixel i), and after it v[q] holds the filters of pixels q L / F ... (q + 1) L / F,
/// each pixel's F filters together. The element at index m = f L + i goes to n = i F + f: m's
/// bits rotated right by log2(L).
template <class D>
HWY_INLINE void TransposeFilters(D d, hn::Vec<D> (&v)[kPixelConvFilters]) {
  RotateElementIndices<static_cast<int>(hwy::FloorLog2(hn::MaxLanes(D())))>(d, v);
}

/// The inverse: v[q] holds L / F pixels' filters together (as the encoder stores a map and its
/// gradient), and after it v[f] holds filter f of the L pixels (lane i: pixel i). Index
/// n = i F + f goes to m = f L + i: n's bits rotated right by log2(F).
template <class D>
HWY_INLINE void TransposePixels(D d, hn::Vec<D> (&v)[kPixelConvFilters]) {
  RotateElementIndices<static_cast<int>(hwy::FloorLog2(kPixelConvFilters))>(d, v);
}

/// One tile of PixelConvForward: `pixels` <= V L consecutive pixels of one output row (`row`:
/// the input at its first pixel) for filters 0..F-1, z = W P + b into z[f][pixel]. Full: every
/// vector of pixels is whole (plain loads); else the loads are masked to the pixels.
template <int V, bool kFull, class D>
HWY_INLINE void PixelConvTile(D d, const PixelConv& g, const float* row, int pixels,
                              float (&z)[kPixelConvFilters][V * hn::MaxLanes(D())]) {
  constexpr int F = kPixelConvFilters, L = static_cast<int>(hn::MaxLanes(D()));
  int part[V];
#pragma GCC unroll 4
  for (int v = 0; v < V; ++v) part[v] = std::clamp(pixels - v * L, 0, L);
  // The blocked nest's order (gemm.hpp): each k block summed from zero, the first plus the bias,
  // the later ones added to that.
  for (int p0 = 0; p0 < g.k; p0 += kProductKBlock) {
    const int p_end = std::min(g.k, p0 + kProductKBlock);
    hn::Vec<D> acc[F][V];
#pragma GCC unroll 8
    for (int f = 0; f < F; ++f) {
#pragma GCC unroll 4
      for (int v = 0; v < V; ++v) acc[f][v] = hn::Zero(d);
    }
    for (int p = p0; p < p_end; ++p) {
      const float* at = row + g.patch_offsets[p];
      hn::Vec<D> x[V];
#pragma GCC unroll 4
      for (int v = 0; v < V; ++v) {
        x[v] = kFull ? hn::LoadU(d, at + v * L) : LoadPart(d, at + v * L, part[v]);
      }
      const float* w = g.weights + static_cast<long>(p) * F;
#pragma GCC unroll 8
      for (int f = 0; f < F; ++f) {
        const auto w_f = hn::Set(d, w[f]);
#pragma GCC unroll 4
        for (int v = 0; v < V; ++v) acc[f][v] = hn::MulAdd(x[v], w_f, acc[f][v]);
      }
    }
#pragma GCC unroll 8
    for (int f = 0; f < F; ++f) {
#pragma GCC unroll 4
      for (int v = 0; v < V; ++v) {
        const auto before = p0 == 0 ? hn::Set(d, g.bias[f]) : hn::Load(d, z[f] + v * L);
        hn::Store(hn::Add(acc[f][v], before), d, z[f] + v * L);
      }
    }
  }
}

inline void PixelConvForward(const PixelConv& g) {
  using D = hn::ScalableTag<float>;
  const D d;
  constexpr int F = kPixelConvFilters, L = static_cast<int>(hn::MaxLanes(D()));
  // V F accumulators, V vectors of pixels and a broadcast: 19 of AVX-512's 32 registers.
  constexpr int V = 2;
  alignas(64) float z[F][V * L];
  for (long r = 0; r < g.rows; ++r) {
    const float* row = g.input + g.pixel_offsets[r * g.width];
    for (int x0 = 0; x0 < g.width; x0 += V * L) {
      const int pixels = std::min(V * L, g.width - x0);
      if (pixels == V * L) {
        PixelConvTile<V, true>(d, g, row + x0, pixels, z);
      } else {
        PixelConvTile<V, false>(d, g, row + x0, pixels, z);
      }
      // The epilogue of each vector of pixels, transposed to each pixel's filters together:
      // SiluForward's operations (silu-inl.h), so the same bits.
      for (int v = 0; v * L < pixels; ++v) {
        hn::Vec<D> t[F];
#pragma GCC unroll 8
        for (int f = 0; f < F; ++f) t[f] = hn::Load(d, z[f] + v * L);
        TransposeFilters(d, t);
        const long first = (r * g.width + x0 + v * L) * F;
        const int floats = std::min(L, pixels - v * L) * F;
#pragma GCC unroll 8
        for (int q = 0; q < F && q * L < floats; ++q) {
          const auto s = Sigmoid(d, t[q]);
          const auto count = static_cast<std::size_t>(std::min(L, floats - q * L));
          StorePart(d, s, g.sigmoid + first + q * L, count);
          StorePart(d, hn::Mul(t[q], s), g.c + first + q * L, count);
        }
      }
    }
  }
}

/// Rows of output pixels per chunk of PixelConvWeights: the chunk's delta (transposed, 1 KB a
/// row of 32 pixels) and the image rows its windows read (~3 KB a row of the default 6-channel
/// image) stay in L1 through the chunk's 2 (K / 6) passes. Measured on the default first layer
/// (bench_kernels, first_layer): 8 rows ~100 GFLOP/s, 16 ~99, 32 ~80, 64 ~70.
constexpr int kWeightChunkRows = 8;

/// One pass of PixelConvWeights over a chunk: for kFilters filters from `filter` and kEntries patch
/// entries from `entry`, the chunk's products summed per lane and added to lane_sums (lanes
/// kept apart: entry e, filter f at lane_sums + (e F + f) L). delta_t holds the chunk's delta
/// transposed, F vectors per vector of pixels (lane i: pixel i, zero past a row's end).
template <int kFilters, int kEntries, bool kFullRows, class D>
HWY_INLINE void PixelWeightTile(D d, const PixelConvGradient& g, long r0, int chunk_rows,
                                const float* delta_t, int filter, int entry, float* lane_sums) {
  constexpr int F = kPixelConvFilters, L = static_cast<int>(hn::MaxLanes(D()));
  const int vectors = (g.width + L - 1) / L;
  hn::Vec<D> acc[kEntries][kFilters];
#pragma GCC unroll 8
  for (int e = 0; e < kEntries; ++e) {
#pragma GCC unroll 8
    for (int f = 0; f < kFilters; ++f) acc[e][f] = hn::Zero(d);
  }
  for (int r = 0; r < chunk_rows; ++r) {
    const float* row = g.input + g.pixel_offsets[(r0 + r) * g.width];
    for (int v = 0; v < vectors; ++v) {
      const float* delta_v = delta_t + (static_cast<long>(r) * vectors + v) * F * L;
      hn::Vec<D> delta[kFilters];
#pragma GCC unroll 8
      for (int f = 0; f < kFilters; ++f) delta[f] = hn::Load(d, delta_v + (filter + f) * L);
      const std::size_t pixels = static_cast<std::size_t>(std::min(L, g.width - v * L));
#pragma GCC unroll 8
      for (int e = 0; e < kEntries; ++e) {
        // Past a row's end delta is zero and the image is not read (a masked load).
        const float* at = row + g.patch_offsets[entry + e] + v * L;
        const auto x = kFullRows ? hn::LoadU(d, at) : LoadPart(d, at, pixels);
#pragma GCC unroll 8
        for (int f = 0; f < kFilters; ++f) acc[e][f] = hn::MulAdd(x, delta[f], acc[e][f]);
      }
    }
  }
#pragma GCC unroll 8
  for (int e = 0; e < kEntries; ++e) {
#pragma GCC unroll 8
    for (int f = 0; f < kFilters; ++f) {
      float* sum = lane_sums + (static_cast<long>(entry + e) * F + filter + f) * L;
      hn::Store(hn::Add(hn::Load(d, sum), acc[e][f]), d, sum);
    }
  }
}

/// dW = delta P^T and db = delta 1 with the pixels in the lanes: each (entry, filter) sum is
/// kept in L partial sums, one per lane, over chunks of kWeightChunkRows rows, and the lanes are
/// added at the end. A tile of 4 filters x 6 entries makes 24 full-width multiply-adds per 10
/// loads; the offset product's tile, with the filters in the lanes, makes one half-width
/// multiply-add per load (each patch value feeds the 8 filters and nothing else).
inline void PixelConvWeights(const PixelConvGradient& g) {
  using D = hn::ScalableTag<float>;
  const D d;
  constexpr int F = kPixelConvFilters, L = static_cast<int>(hn::MaxLanes(D()));
  constexpr int kTileFilters = 4, kTileEntries = 6;
  const int vectors = (g.width + L - 1) / L;
  auto lane_sums = hwy::AllocateAligned<float>(static_cast<std::size_t>(g.k + 1) * F * L);
  auto delta_t = hwy::AllocateAligned<float>(
      static_cast<std::size_t>(std::min<long>(kWeightChunkRows, g.rows)) * vectors * F * L);
  std::fill(lane_sums.get(), lane_sums.get() + static_cast<std::size_t>(g.k + 1) * F * L, 0.0f);
  float* bias_sums = lane_sums.get() + static_cast<long>(g.k) * F * L;
  for (long r0 = 0; r0 < g.rows; r0 += kWeightChunkRows) {
    const int chunk_rows = static_cast<int>(std::min<long>(kWeightChunkRows, g.rows - r0));
    // The chunk's delta, each vector of pixels transposed to its filters; db's lanes on the way.
    hn::Vec<D> bias[F];
#pragma GCC unroll 8
    for (int f = 0; f < F; ++f) bias[f] = hn::Load(d, bias_sums + f * L);
    for (int r = 0; r < chunk_rows; ++r) {
      for (int v = 0; v < vectors; ++v) {
        const float* in = g.delta + ((r0 + r) * g.width + static_cast<long>(v) * L) * F;
        const int floats = std::min(L, g.width - v * L) * F;
        hn::Vec<D> t[F];
#pragma GCC unroll 8
        for (int q = 0; q < F; ++q) {
          t[q] =
              LoadPart(d, in + q * L, static_cast<std::size_t>(std::clamp(floats - q * L, 0, L)));
        }
        TransposePixels(d, t);
        float* out = delta_t.get() + (static_cast<long>(r) * vectors + v) * F * L;
#pragma GCC unroll 8
        for (int f = 0; f < F; ++f) {
          hn::Store(t[f], d, out + f * L);
          bias[f] = hn::Add(bias[f], t[f]);
        }
      }
    }
#pragma GCC unroll 8
    for (int f = 0; f < F; ++f) hn::Store(bias[f], d, bias_sums + f * L);
    for (int filter = 0; filter < F; filter += kTileFilters) {
      int entry = 0;
      for (; entry + kTileEntries <= g.k; entry += kTileEntries) {
        if (g.width % L == 0) {
          PixelWeightTile<kTileFilters, kTileEntries, true>(d, g, r0, chunk_rows, delta_t.get(),
                                                            filter, entry, lane_sums.get());
        } else {
          PixelWeightTile<kTileFilters, kTileEntries, false>(d, g, r0, chunk_rows, delta_t.get(),
                                                             filter, entry, lane_sums.get());
        }
      }
      for (; entry < g.k; ++entry) {
        PixelWeightTile<kTileFilters, 1, false>(d, g, r0, chunk_rows, delta_t.get(), filter, entry,
                                                lane_sums.get());
      }
    }
  }
  for (int e = 0; e < g.k; ++e) {
    for (int f = 0; f < F; ++f) {
      g.d_weights[static_cast<long>(e) * F + f] = hn::GetLane(
          hn::SumOfLanes(d, hn::Load(d, lane_sums.get() + (static_cast<long>(e) * F + f) * L)));
    }
  }
  for (int f = 0; f < F; ++f)
    g.d_bias[f] = hn::GetLane(hn::SumOfLanes(d, hn::Load(d, bias_sums + f * L)));
}

#endif  // the portable targets

inline void Deinterleave(std::ptrdiff_t n, const float* x, const float* mean,
                         const float* inv_scale, float* even, float* odd) {
  std::ptrdiff_t i = 0;
#if HWY_TARGET != HWY_SCALAR
  const hn::ScalableTag<float> d;
  const std::ptrdiff_t step = 2 * static_cast<std::ptrdiff_t>(hn::Lanes(d));
  const auto load = [&](std::ptrdiff_t at) {
    const auto v = hn::LoadU(d, x + at);
    return mean == nullptr
               ? v
               : hn::Mul(hn::Sub(v, hn::LoadU(d, mean + at)), hn::LoadU(d, inv_scale + at));
  };
  for (; i + step <= n; i += step) {
    const auto lower = load(i), upper = load(i + step / 2);
    hn::StoreU(hn::ConcatEven(d, upper, lower), d, even + i / 2);
    hn::StoreU(hn::ConcatOdd(d, upper, lower), d, odd + i / 2);
  }
#endif
  for (; i < n; ++i) {
    // Two statements: the subtraction is rounded before the product, as in the vectors.
    float v = x[i];
    if (mean != nullptr) {
      v -= mean[i];
      v *= inv_scale[i];
    }
    (i % 2 == 0 ? even : odd)[i / 2] = v;
  }
}

// Only the input gradient of a first layer runs it (training does not): a plain loop.
inline void Row2im(const ConvPatches& g, const float* rows, long ld, float* image) {
  const long step = g.stride * g.column_stride;
  ForEachPatchLine(
      g,
      [&](long p, long j, long pixel, int count) {
        const float* in = rows + j + p * ld;
        for (int i = 0; i < count; ++i) image[pixel + i * step] += in[i];
      },
      [](long, long, int) {});
}

}  // namespace handcentric::policy::kernels::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();
