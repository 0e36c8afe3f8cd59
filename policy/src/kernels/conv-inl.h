// Private, per target: im2col and col2im (kernel_set.hpp, ConvPatches), the data movement around
// the convolution's products; the products themselves are the GEMM driver's.

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

inline void Im2col(const ConvPatches& g, const float* image, float* patches) {
  const hn::ScalableTag<float> d;
  const long k = static_cast<long>(g.kernel) * g.kernel * g.channels;
  float* out = patches;
  for (int b = 0; b < g.batch; ++b) {
    const long sample = b * g.sample_stride;
    for (int oy = 0; oy < g.out_height; ++oy) {
      for (int ox = 0; ox < g.out_width; ++ox, out += k) {
        ForEachPatchRun(
            g, sample, oy, ox,
            [&](int at, long pixel, int count) HWY_ATTR {
              if (count == 1) {
                out[at] = image[pixel];
                return;
              }
              ForEachVector(d, count, [&](std::ptrdiff_t i, std::size_t n) HWY_ATTR {
                StorePart(d, LoadPart(d, image + pixel + i, n), out + at + i, n);
              });
            },
            [&](int at, int count) { std::fill(out + at, out + at + count, 0.0f); });
      }
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

}  // namespace handcentric::policy::kernels::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();
