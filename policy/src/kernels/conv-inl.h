// Private, per target: col2im and row2im (kernel_set.hpp, ConvPatches), which add a patch
// matrix's gradient back onto the pixels its entries were read from (the input gradient of a
// convolution). The forward products read their patches in place (OffsetGemm), so nothing
// writes a patch matrix; the products themselves are the GEMM driver's.

#include <algorithm>
#include <cstddef>

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
