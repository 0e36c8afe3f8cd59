// Private, per target: Box-Muller's pairs (box_muller.hpp) in double lanes, with glibc 2.36's
// logf, sinf and cosf transcribed operation for operation, so each float result has libm's bits.
// glibc picks the variants of those functions compiled with -mfma -mavx2 on the CPUs these
// targets run on, where GCC contracts every a * b + c of them into one fused multiply-add: so
// does MulAdd here, and the other operations (products, conversions, the final rounding to
// float) are the same IEEE operations in the same order. -ffp-contract stays off in this build
// (ISO C++20: GCC's default), so the plain Mul and Add are not fused behind our back either.
// Only AVX2 and AVX-512 use this (kernels.cpp): without FMA, MulAdd rounds twice.

#include <cstddef>
#include <cstdint>

#include <hwy/highway.h>

#include "box_muller.hpp"

// The targets with FMA only (the condition of kernels.cpp); after lanes-inl.h.
#if HWY_TARGET == HWY_AVX2 || HWY_TARGET == HWY_AVX3
HWY_BEFORE_NAMESPACE();
namespace handcentric::policy::kernels::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

/// The parts of one vector of pairs, each as many floats as D has doubles.
template <class D>
struct BoxMullerLanes {
  hn::Vec<hn::Rebind<float, D>> radius, cosine, sine;
};

/// m as a double, for 0 <= m < 2^52: its bits under the exponent of 2^52, minus 2^52 (exact).
template <class D>
HWY_INLINE hn::Vec<D> SmallUnsignedToDouble(D d, hn::Vec<hn::RebindToUnsigned<D>> m) {
  const hn::RebindToUnsigned<D> du;
  return hn::Sub(hn::BitCast(d, hn::Or(m, hn::Set(du, 0x4330000000000000ull))), hn::Set(d, 0x1p52));
}

/// logf(u1) of glibc (e_logf.c) as a double before its rounding to float, for u1 a normal float
/// held in double lanes. glibc reads the float's bits ix: tmp = ix - 0x3f330000, table index
/// i = (tmp >> 19) mod 16, k = tmp >> 23 (arithmetic), z = u1 2^-k in [0.7, 1.4). The float's
/// bits are the double's shifted right by 29 less 896 << 23 (the exponent biases 1023 and 127).
/// glibc's x == 1 case returns 0, which the table's entry {1, 0} gives too.
template <class D>
HWY_INLINE hn::Vec<D> GlibcLogf(D d, hn::Vec<D> u1, const LibmFloatConstants& c) {
  const hn::RebindToSigned<D> di;
  const auto bits = hn::BitCast(di, u1);
  const auto ix = hn::Sub(hn::ShiftRight<29>(bits), hn::Set(di, std::int64_t{896} << 23));
  const auto tmp = hn::Sub(ix, hn::Set(di, 0x3f330000));
  const auto index = hn::And(hn::ShiftRight<19>(tmp), hn::Set(di, 15));
  const auto k = hn::ShiftRight<23>(tmp);  // arithmetic: tmp < 0 for u1 < 0.7
  const auto z = hn::BitCast(d, hn::Sub(bits, hn::ShiftLeft<52>(k)));
#if HWY_TARGET == HWY_AVX3
  // The 16-entry tables in two registers each, one two-table permute per lookup instead of a
  // gather (Highway 1.0 has no two-table lookup): exact copies either way.
  const auto lookup = [&](const double* table) HWY_ATTR {
    return hn::Vec<D>{
        _mm512_permutex2var_pd(hn::LoadU(d, table).raw, index.raw, hn::LoadU(d, table + 8).raw)};
  };
  const auto invc = lookup(c.log_invc), logc = lookup(c.log_logc);
#else
  const auto invc = hn::GatherIndex(d, c.log_invc, index);
  const auto logc = hn::GatherIndex(d, c.log_logc, index);
#endif
  // k as a double: k + 1.5 2^52 has k in its low bits, for |k| < 2^51.
  const auto kd =
      hn::Sub(hn::BitCast(d, hn::Add(k, hn::Set(di, 0x4338000000000000ll))), hn::Set(d, 0x1.8p52));
  const auto r = hn::MulAdd(z, invc, hn::Set(d, -1.0));         // r = z invc - 1
  const auto y0 = hn::MulAdd(kd, hn::Set(d, c.log_ln2), logc);  // y0 = logc + k Ln2
  const auto r2 = hn::Mul(r, r);
  auto y = hn::MulAdd(hn::Set(d, c.log_poly[1]), r, hn::Set(d, c.log_poly[2]));
  y = hn::MulAdd(hn::Set(d, c.log_poly[0]), r2, y);
  return hn::MulAdd(y, r2, hn::Add(y0, r));  // y r2 + (y0 + r)
}

/// glibc's sinf_poly (sincosf.h) for even n, the sine, of the signed reduced x, and for odd n,
/// the cosine, of x2 = x^2; the cosine of the second table is the negated first.
template <class D>
HWY_INLINE hn::Vec<D> GlibcSinPoly(D d, hn::Vec<D> x, hn::Vec<D> x2, const LibmFloatConstants& c) {
  const auto x3 = hn::Mul(x, x2);
  const auto s1 = hn::MulAdd(x2, hn::Set(d, c.sin_poly[2]), hn::Set(d, c.sin_poly[1]));
  const auto x7 = hn::Mul(x3, x2);
  const auto s = hn::MulAdd(x3, hn::Set(d, c.sin_poly[0]), x);
  return hn::MulAdd(x7, s1, s);
}

template <class D>
HWY_INLINE hn::Vec<D> GlibcCosPoly(D d, hn::Vec<D> x2, const LibmFloatConstants& c) {
  const auto x4 = hn::Mul(x2, x2);
  const auto c2 = hn::MulAdd(x2, hn::Set(d, c.cos_poly[4]), hn::Set(d, c.cos_poly[3]));
  const auto c1 = hn::MulAdd(x2, hn::Set(d, c.cos_poly[1]), hn::Set(d, c.cos_poly[0]));
  const auto x6 = hn::Mul(x4, x2);
  const auto cc = hn::MulAdd(x4, hn::Set(d, c.cos_poly[2]), c1);
  return hn::MulAdd(x6, c2, cc);
}

/// The radius and the cosine and sine of one vector of draws (box_muller.hpp).
template <class D>
HWY_INLINE BoxMullerLanes<D> BoxMullerOf(D d, hn::Vec<hn::RebindToUnsigned<D>> draws,
                                         const LibmFloatConstants& c) {
  const hn::RebindToUnsigned<D> du;
  const hn::Rebind<float, D> df;
  const auto high = hn::ShiftRight<40>(draws);
  const auto low = hn::And(hn::ShiftRight<8>(draws), hn::Set(du, 0xFFFFFFull));
  // u1 = (hi + 1) 2^-24 and u2 = lo 2^-24 are exact in float and in double.
  const auto u1 =
      hn::Mul(SmallUnsignedToDouble(d, hn::Add(high, hn::Set(du, 1))), hn::Set(d, 0x1p-24));
  const auto u2 = hn::Mul(SmallUnsignedToDouble(d, low), hn::Set(d, 0x1p-24));

  // radius = sqrtf(-2 logf(u1)): -2 times a float is exact, sqrt rounds once in float.
  const auto log_u1 = hn::DemoteTo(df, GlibcLogf(d, u1, c));
  const auto radius = hn::Sqrt(hn::Mul(hn::Set(df, -2.0f), log_u1));

  // The float angle 2 pi u2: the product of two 24-bit significands is exact in double, so one
  // rounding to float gives the float product.
  const float two_pi = 2.0f * 3.14159265358979323846f;
  const auto angle_f = hn::DemoteTo(df, hn::Mul(hn::Set(d, static_cast<double>(two_pi)), u2));
  const auto angle = hn::PromoteTo(d, angle_f);
  // glibc's reduce_fast without TOINT_INTRINSICS: r = x (2 / pi) 2^24, n = ((int32) r + 2^23)
  // >> 24, the same as floor((trunc(r) + 2^23) 2^-24) here (0 <= r < 2^27: all exact); then
  // x - n pi / 2 in one fused operation. n = 0 below pi / 4 leaves x itself, as glibc's path
  // for |x| < 0.75 does; n is 0 to 4 for angles below 2 pi.
  const auto r = hn::Mul(angle, hn::Set(d, c.sincos_hpi_inv));
  const auto n = hn::Floor(hn::Mul(hn::Add(hn::Trunc(r), hn::Set(d, 0x1p23)), hn::Set(d, 0x1p-24)));
  const auto x = hn::NegMulAdd(n, hn::Set(d, c.sincos_hpi), angle);
  const auto is1 = hn::Eq(n, hn::Set(d, 1.0)), is2 = hn::Eq(n, hn::Set(d, 2.0)),
             is3 = hn::Eq(n, hn::Set(d, 3.0));
  // sign[n & 3] = {1, -1, -1, 1}: the sine polynomial runs on -x in quadrants 1 and 2.
  const auto signed_x = hn::IfThenElse(hn::Or(is1, is2), hn::Neg(x), x);
  const auto x2 = hn::Mul(x, x);
  const auto sine_poly = GlibcSinPoly(d, signed_x, x2, c);
  auto cosine_poly = GlibcCosPoly(d, x2, c);
  cosine_poly = hn::IfThenElse(hn::Or(is2, is3), hn::Neg(cosine_poly), cosine_poly);  // n & 2
  const auto odd = hn::Or(is1, is3);  // sinf takes the cosine polynomial, cosf the sine
  auto sine = hn::DemoteTo(df, hn::IfThenElse(odd, cosine_poly, sine_poly));
  auto cosine = hn::DemoteTo(df, hn::IfThenElse(odd, sine_poly, cosine_poly));
  // Below 2^-12 glibc returns sinf(x) = x and cosf(x) = 1.
  const auto tiny = hn::Lt(angle_f, hn::Set(df, 0x1p-12f));
  sine = hn::IfThenElse(tiny, angle_f, sine);
  cosine = hn::IfThenElse(tiny, hn::Set(df, 1.0f), cosine);
  return {radius, cosine, sine};
}

/// body(i, count, parts) for each vector of draws from bits[i]: full vectors read in place, the
/// tail (count < Lanes) through a zero-padded copy (a zero draw is a valid input; body stores
/// the first `count` lanes only).
template <class Body>
HWY_INLINE void ForEachDrawVector(std::ptrdiff_t pairs, const std::uint64_t* bits,
                                  const LibmFloatConstants& c, Body&& body) {
  const hn::ScalableTag<double> d;
  const hn::RebindToUnsigned<decltype(d)> du;
  constexpr std::size_t kLanes = hn::MaxLanes(decltype(d)());
  ForEachVector(du, pairs, [&](std::ptrdiff_t i, std::size_t count) HWY_ATTR {
    alignas(64) std::uint64_t padded[kLanes] = {};
    const bool full = count == kLanes;
    for (std::size_t j = 0; !full && j < count; ++j)
      padded[j] = bits[i + static_cast<std::ptrdiff_t>(j)];
    body(i, count, BoxMullerOf(d, full ? hn::LoadU(du, bits + i) : hn::Load(du, padded), c));
  });
}

/// KernelSet::box_muller_parts.
inline void BoxMullerParts(std::ptrdiff_t pairs, const std::uint64_t* bits, float* radius,
                           float* cosine, float* sine, const LibmFloatConstants& c) {
  const hn::Rebind<float, hn::ScalableTag<double>> df;
  ForEachDrawVector(pairs, bits, c,
                    [&](std::ptrdiff_t i, std::size_t count, const auto& parts) HWY_ATTR {
                      StorePart(df, parts.radius, radius + i, count);
                      StorePart(df, parts.cosine, cosine + i, count);
                      StorePart(df, parts.sine, sine + i, count);
                    });
}

/// KernelSet::box_muller.
inline void BoxMullerPairs(std::ptrdiff_t pairs, const std::uint64_t* bits, float* out,
                           const LibmFloatConstants& c) {
  const hn::Rebind<float, hn::ScalableTag<double>> df;
  constexpr std::size_t kLanes = hn::MaxLanes(decltype(df)());
  ForEachDrawVector(pairs, bits, c,
                    [&](std::ptrdiff_t i, std::size_t count, const auto& parts) HWY_ATTR {
                      // out = (r cos, r sin) interleaved: two float products, as the scalar code
                      // has them.
                      const auto first = hn::Mul(parts.radius, parts.cosine);
                      const auto second = hn::Mul(parts.radius, parts.sine);
                      if (count == kLanes) {
                        hn::StoreInterleaved2(first, second, df, out + 2 * i);
                      } else {
                        alignas(64) float pair_values[2 * kLanes];
                        hn::StoreInterleaved2(first, second, df, pair_values);
                        for (std::size_t j = 0; j < 2 * count; ++j)
                          out[2 * i + static_cast<std::ptrdiff_t>(j)] = pair_values[j];
                      }
                    });
}

}  // namespace handcentric::policy::kernels::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();
#endif  // HWY_TARGET == HWY_AVX2 || HWY_TARGET == HWY_AVX3
