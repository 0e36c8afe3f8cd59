// AVX-512 F kernels. Every function that uses AVX-512 carries the target attribute, and the
// translation unit is compiled for the baseline target: no template or inline function of
// another header is compiled for AVX-512 here, so nothing AVX-512 can leak into the rest of the
// program through the linker's choice of one copy of an inline function. avx512_kernels() is only
// used after kernel_isa_supported(KernelIsa::avx512) said yes.
#include <immintrin.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>

#include "asan_lanes.hpp"
#include "kernel_set.hpp"
#include "pack.hpp"

#define HC_AVX512 __attribute__((target("avx512f,fma")))

namespace handcentric::policy::kernels {
namespace {

// The masked accesses, through asan_lanes.hpp's check (empty without ASan).
HC_AVX512 inline __attribute__((always_inline)) __m512 maskz_loadu(__mmask16 mask, const float* p) {
  check_lanes(p, mask, sizeof(float), false);
  return _mm512_maskz_loadu_ps(mask, p);
}
HC_AVX512 inline __attribute__((always_inline)) void mask_storeu(float* p, __mmask16 mask, __m512 value) {
  check_lanes(p, mask, sizeof(float), true);
  _mm512_mask_storeu_ps(p, mask, value);
}
HC_AVX512 inline __attribute__((always_inline)) __m512i maskz_loadu_epi64(__mmask8 mask, const std::uint64_t* p) {
  check_lanes(p, mask, sizeof(std::uint64_t), false);
  return _mm512_maskz_loadu_epi64(mask, p);
}
// Lane i reads base[index[i]] when `mask` enables it, else 0.
HC_AVX512 inline __attribute__((always_inline)) __m512 mask_gather(__mmask16 mask, __m512i index, const float* base) {
#if defined(__SANITIZE_ADDRESS__)
  alignas(64) int offsets[16];
  _mm512_store_si512(offsets, index);
  for (int i = 0; i < 16; ++i) {
    if ((mask >> i) & 1) check_lanes(base + offsets[i], 1, sizeof(float), false);
  }
#endif
  return _mm512_mask_i32gather_ps(_mm512_setzero_ps(), mask, index, base, 4);
}

HC_AVX512 void silu_forward(std::ptrdiff_t n, const float* z, float* s, float* a);
HC_AVX512 void silu(std::ptrdiff_t n, float* x);
HC_AVX512 void silu_backward(std::ptrdiff_t n, const float* a, const float* s, float* delta);

// One narrow product C(rows, 0:N) = A(rows, 0:k) op(B)(0:k, 0:N) (+ bias) with N x V accumulators:
// the contract of pack.hpp's narrow loop nest ("Narrow products").
template <int N, int V>
HC_AVX512 void narrow_product(int shift, int rows, int k, const float* a, long lda, const float* b, long b_step,
                              long b_stride, const float* bias, float* c, long ldc) {
  const int lanes = shift + rows;  // in 16 (V - 1) + 1 .. 16 V
  __mmask16 head = static_cast<__mmask16>(0xFFFFu << shift);
  const int tail_lanes = lanes - 16 * (V - 1);
  __mmask16 tail = static_cast<__mmask16>(tail_lanes >= 16 ? 0xFFFFu : (1u << tail_lanes) - 1u);
  if constexpr (V == 1) head = tail = static_cast<__mmask16>(head & tail);
  const auto mask = [&](int v) { return v == 0 ? head : v + 1 == V ? tail : static_cast<__mmask16>(0xFFFF); };
  a -= shift;
  c -= shift;
  if (bias != nullptr) bias -= shift;
  __m512 acc[N][V];
  #pragma GCC unroll 32
  for (int v = 0; v < V; ++v) {
    const __m512 start = bias != nullptr ? maskz_loadu(mask(v), bias + 16 * v) : _mm512_setzero_ps();
    #pragma GCC unroll 16
    for (int j = 0; j < N; ++j) acc[j][v] = start;
  }
  for (int p = 0; p < k; ++p) {
    const float* column = a + p * lda;
    const float* b_row = b + p * b_step;
    // No software prefetch: measured (n = 1), prefetching 2, 4 or 8 columns ahead changed nothing.
    #pragma GCC unroll 32
    for (int v = 0; v < V; ++v) {
      const __m512 a_v = v == 0 || v + 1 == V ? maskz_loadu(mask(v), column + 16 * v)
                                               : _mm512_loadu_ps(column + 16 * v);
      #pragma GCC unroll 16
      for (int j = 0; j < N; ++j) acc[j][v] = _mm512_fmadd_ps(a_v, _mm512_set1_ps(b_row[j * b_stride]), acc[j][v]);
    }
  }
  #pragma GCC unroll 16
  for (int j = 0; j < N; ++j) {
    #pragma GCC unroll 32
    for (int v = 0; v < V; ++v) mask_storeu(c + j * ldc + 16 * v, mask(v), acc[j][v]);
  }
}

// C tile of 32 x 12 = 24 zmm accumulators; per k: 2 loads of A, 12 broadcasts of B, 24 FMAs.
struct Avx512Kernel {
  static constexpr int MR = 32, NR = 12;
  static constexpr int kNarrowLanes = 16, kNarrowAccumulators = 24, kNarrowGroup = 8;
  template <int N, int V>
  static constexpr auto narrow_block = &narrow_product<N, V>;
  static constexpr SiluFunctions kSilu{silu_forward, silu, silu_backward};

  // pack_a<MR> with vector moves: op(A) = A copies two (masked) vectors per k; op(A) = A^T
  // gathers each row panel's k-th column (16 rows at stride lda) from rows that stay in L1.
  HC_AVX512 static void pack_a(Op op, const float* a, int lda, int i0, int mc, int p0, int kc, float* out) {
    if (op == Op::transpose && static_cast<long>(lda) * 16 >= (1L << 29)) {  // offsets beyond int32 bytes
      kernels::pack_a<MR>(op, a, lda, i0, mc, p0, kc, out);
      return;
    }
    const __m512i rows_apart = _mm512_mullo_epi32(_mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15),
                                                  _mm512_set1_epi32(lda));
    for (int panel = 0; panel < mc; panel += MR) {
      const int rows = std::min(MR, mc - panel);
      const __mmask16 mask0 = static_cast<__mmask16>(rows >= 16 ? 0xFFFFu : (1u << rows) - 1u);
      const __mmask16 mask1 = static_cast<__mmask16>(rows >= 32 ? 0xFFFFu : rows <= 16 ? 0u : (1u << (rows - 16)) - 1u);
      if (op == Op::none) {
        const float* column = a + (i0 + panel) + static_cast<long>(p0) * lda;
        for (int p = 0; p < kc; ++p, column += lda) {
          _mm512_store_ps(out + p * MR, maskz_loadu(mask0, column));
          _mm512_store_ps(out + p * MR + 16, maskz_loadu(mask1, column + 16));
        }
      } else {
        const float* row0 = a + p0 + static_cast<long>(i0 + panel) * lda;  // op(A)(i, p) = a[p + i lda]
        const float* row16 = rows > 16 ? row0 + 16L * lda : row0;  // unused (mask 0) when rows <= 16
        for (int p = 0; p < kc; ++p) {
          _mm512_store_ps(out + p * MR, mask_gather(mask0, rows_apart, row0 + p));
          _mm512_store_ps(out + p * MR + 16,
                          mask_gather(mask1, rows_apart, row16 + p));
        }
      }
      out += static_cast<long>(kc) * MR;
    }
  }

  template <BLayout layout>
  HC_AVX512 static void tile(int kc, const float* a, const float* b, int ldb, float* c, int ldc, bool accumulate,
                             const float* bias) {
    __m512 acc[NR][2];
    #pragma GCC unroll 32
    for (int j = 0; j < NR; ++j) acc[j][0] = acc[j][1] = _mm512_setzero_ps();
    for (int p = 0; p < kc; ++p) {
      const __m512 a0 = _mm512_load_ps(a), a1 = _mm512_load_ps(a + 16);
      _mm_prefetch(reinterpret_cast<const char*>(a + 8 * MR), _MM_HINT_T0);
      #pragma GCC unroll 32
      for (int j = 0; j < NR; ++j) {
        const __m512 bj = _mm512_set1_ps(layout == BLayout::columns ? b[j * static_cast<long>(ldb)] : b[j]);
        acc[j][0] = _mm512_fmadd_ps(a0, bj, acc[j][0]);
        acc[j][1] = _mm512_fmadd_ps(a1, bj, acc[j][1]);
      }
      a += MR;
      b += layout == BLayout::packed ? NR : layout == BLayout::rows ? ldb : 1;
    }
    if (accumulate) {
      #pragma GCC unroll 32
      for (int j = 0; j < NR; ++j) {
        float* cj = c + static_cast<long>(j) * ldc;
        _mm512_storeu_ps(cj, _mm512_add_ps(acc[j][0], _mm512_loadu_ps(cj)));
        _mm512_storeu_ps(cj + 16, _mm512_add_ps(acc[j][1], _mm512_loadu_ps(cj + 16)));
      }
    } else {
      __m512 bias0 = _mm512_setzero_ps(), bias1 = _mm512_setzero_ps();
      if (bias != nullptr) {
        bias0 = _mm512_loadu_ps(bias);
        bias1 = _mm512_loadu_ps(bias + 16);
      }
      #pragma GCC unroll 32
      for (int j = 0; j < NR; ++j) {
        float* cj = c + static_cast<long>(j) * ldc;
        _mm512_storeu_ps(cj, _mm512_add_ps(acc[j][0], bias0));
        _mm512_storeu_ps(cj + 16, _mm512_add_ps(acc[j][1], bias1));
      }
    }
  }
};

// exp(x) by ExpPolynomial (kernel_set.hpp), times 2^n by scalef, which also gives 0 and +inf
// past the ends; x is clamped to +-88.7 first.
HC_AVX512 __m512 exp_ps(__m512 x) {
  x = _mm512_min_ps(_mm512_max_ps(x, _mm512_set1_ps(-88.7f)), _mm512_set1_ps(88.7f));
  const __m512 n = _mm512_roundscale_ps(_mm512_mul_ps(x, _mm512_set1_ps(ExpPolynomial::kLog2e)),
                                        _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
  __m512 r = _mm512_fnmadd_ps(n, _mm512_set1_ps(ExpPolynomial::kLn2High), x);
  r = _mm512_fnmadd_ps(n, _mm512_set1_ps(ExpPolynomial::kLn2Low), r);
  __m512 p = _mm512_set1_ps(ExpPolynomial::kC[0]);
#pragma GCC unroll 5
  for (int i = 1; i < 6; ++i) p = _mm512_fmadd_ps(p, r, _mm512_set1_ps(ExpPolynomial::kC[i]));
  p = _mm512_fmadd_ps(p, _mm512_mul_ps(r, r), _mm512_add_ps(r, _mm512_set1_ps(1.0f)));
  return _mm512_scalef_ps(p, n);
}

// 1 / d for a positive normal d: rcp14 and one Newton step (relative error ~1e-8; a division
// costs several times more). Past 2^126 the result flushes to 0, as 1 / d is subnormal there.
HC_AVX512 __m512 reciprocal_ps(__m512 d) {
  const __m512 r = _mm512_rcp14_ps(d);
  return _mm512_mul_ps(r, _mm512_fnmadd_ps(d, r, _mm512_set1_ps(2.0f)));
}

HC_AVX512 __m512 sigmoid_ps(__m512 z) {
  const __m512 one = _mm512_set1_ps(1.0f);
  return reciprocal_ps(_mm512_add_ps(one, exp_ps(_mm512_sub_ps(_mm512_setzero_ps(), z))));
}

HC_AVX512 __mmask16 tail_mask(std::ptrdiff_t remaining) {
  return remaining >= 16 ? static_cast<__mmask16>(0xFFFF) : static_cast<__mmask16>((1u << remaining) - 1u);
}

HC_AVX512 void silu_forward(std::ptrdiff_t n, const float* z, float* s, float* a) {
  for (std::ptrdiff_t i = 0; i < n; i += 16) {
    const __mmask16 mask = tail_mask(n - i);
    const __m512 zi = maskz_loadu(mask, z + i);
    const __m512 si = sigmoid_ps(zi);
    mask_storeu(s + i, mask, si);
    mask_storeu(a + i, mask, _mm512_mul_ps(zi, si));
  }
}

HC_AVX512 void silu_backward(std::ptrdiff_t n, const float* a, const float* s, float* delta) {
  const __m512 one = _mm512_set1_ps(1.0f);
  for (std::ptrdiff_t i = 0; i < n; i += 16) {
    const __mmask16 mask = tail_mask(n - i);
    const __m512 ai = maskz_loadu(mask, a + i), si = maskz_loadu(mask, s + i);
    const __m512 derivative = _mm512_fmadd_ps(ai, _mm512_sub_ps(one, si), si);  // s + a (1 - s)
    mask_storeu(delta + i, mask, _mm512_mul_ps(maskz_loadu(mask, delta + i), derivative));
  }
}

HC_AVX512 void silu(std::ptrdiff_t n, float* x) {
  for (std::ptrdiff_t i = 0; i < n; i += 16) {
    const __mmask16 mask = tail_mask(n - i);
    const __m512 xi = maskz_loadu(mask, x + i);
    mask_storeu(x + i, mask, _mm512_mul_ps(xi, sigmoid_ps(xi)));
  }
}

HC_AVX512 double squared_norm(std::ptrdiff_t n, const float* g) {
  __m512d sum0 = _mm512_setzero_pd(), sum1 = _mm512_setzero_pd();
  for (std::ptrdiff_t i = 0; i < n; i += 16) {
    const __m512 gi = maskz_loadu(tail_mask(n - i), g + i);
    const __m512d lo = _mm512_cvtps_pd(_mm512_castps512_ps256(gi));
    const __m512d hi = _mm512_cvtps_pd(_mm256_castpd_ps(_mm512_extractf64x4_pd(_mm512_castps_pd(gi), 1)));
    sum0 = _mm512_fmadd_pd(lo, lo, sum0);
    sum1 = _mm512_fmadd_pd(hi, hi, sum1);
  }
  return _mm512_reduce_add_pd(_mm512_add_pd(sum0, sum1));
}

HC_AVX512 void adam(const AdamUpdate& u) {
  const __m512 b1 = _mm512_set1_ps(u.beta1), c1 = _mm512_set1_ps(1.0f - u.beta1);
  const __m512 b2 = _mm512_set1_ps(u.beta2), c2 = _mm512_set1_ps(1.0f - u.beta2);
  const __m512 step = _mm512_set1_ps(u.step_size), scale = _mm512_set1_ps(u.inv_sqrt_bias2);
  const __m512 eps = _mm512_set1_ps(u.epsilon), decay = _mm512_set1_ps(u.decay);
  const __m512 gradient_scale = _mm512_set1_ps(u.gradient_scale);
  for (std::ptrdiff_t i = 0; i < u.n; i += 16) {
    const __mmask16 mask = tail_mask(u.n - i);
    const __m512 g = _mm512_mul_ps(maskz_loadu(mask, u.gradient + i), gradient_scale);
    const __m512 m = _mm512_fmadd_ps(b1, maskz_loadu(mask, u.m + i), _mm512_mul_ps(c1, g));
    const __m512 v = _mm512_fmadd_ps(b2, maskz_loadu(mask, u.v + i), _mm512_mul_ps(c2, _mm512_mul_ps(g, g)));
    __m512 p = maskz_loadu(mask, u.parameters + i);
    if (u.decay != 1.0f) p = _mm512_mul_ps(p, decay);
    p = _mm512_fnmadd_ps(_mm512_mul_ps(step, m), reciprocal_ps(_mm512_fmadd_ps(_mm512_sqrt_ps(v), scale, eps)), p);
    mask_storeu(u.m + i, mask, m);
    mask_storeu(u.v + i, mask, v);
    mask_storeu(u.parameters + i, mask, p);
  }
}

// ln x for x in [2^-24, 1]: x = 2^e m with m in [sqrt(1/2), sqrt(2)), ln m = 2 atanh(s),
// s = (m - 1) / (m + 1), |s| <= 0.172, by its series to s^9 (error < 1e-9).
HC_AVX512 __m512 log_unit_ps(__m512 x) {
  __m512 e = _mm512_getexp_ps(x);
  __m512 m = _mm512_getmant_ps(x, _MM_MANT_NORM_1_2, _MM_MANT_SIGN_src);
  const __mmask16 big = _mm512_cmp_ps_mask(m, _mm512_set1_ps(BoxMullerPolynomials::kSqrt2), _CMP_GT_OQ);
  m = _mm512_mask_mul_ps(m, big, m, _mm512_set1_ps(0.5f));
  e = _mm512_mask_add_ps(e, big, e, _mm512_set1_ps(1.0f));
  const __m512 one = _mm512_set1_ps(1.0f);
  const __m512 s = _mm512_div_ps(_mm512_sub_ps(m, one), _mm512_add_ps(m, one)), s2 = _mm512_mul_ps(s, s);
  __m512 series = _mm512_set1_ps(BoxMullerPolynomials::kLog[0]);
  for (int i = 1; i < 4; ++i) series = _mm512_fmadd_ps(series, s2, _mm512_set1_ps(BoxMullerPolynomials::kLog[i]));
  series = _mm512_fmadd_ps(series, s2, one);
  return _mm512_fmadd_ps(e, _mm512_set1_ps(BoxMullerPolynomials::kLn2), _mm512_mul_ps(_mm512_add_ps(s, s), series));
}

// cos and sin of 2 pi u for u in [0, 1): q = round(4 u), t = 2 pi (u - q / 4) in [-pi/4, pi/4]
// (u - q / 4 is exact), Taylor polynomials to t^9 / t^8 (error < 3e-8), then the quadrant q.
HC_AVX512 void cos_sin_turns_ps(__m512 u, __m512& c, __m512& s) {
  const __m512 q = _mm512_roundscale_ps(_mm512_mul_ps(u, _mm512_set1_ps(4.0f)), _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
  const __m512 t = _mm512_mul_ps(_mm512_fnmadd_ps(q, _mm512_set1_ps(0.25f), u), _mm512_set1_ps(BoxMullerPolynomials::kTwoPi));
  const __m512 t2 = _mm512_mul_ps(t, t);
  __m512 sin_t = _mm512_set1_ps(BoxMullerPolynomials::kSin[0]), cos_t = _mm512_set1_ps(BoxMullerPolynomials::kCos[0]);
  for (int i = 1; i < 4; ++i) {
    sin_t = _mm512_fmadd_ps(sin_t, t2, _mm512_set1_ps(BoxMullerPolynomials::kSin[i]));
    cos_t = _mm512_fmadd_ps(cos_t, t2, _mm512_set1_ps(BoxMullerPolynomials::kCos[i]));
  }
  sin_t = _mm512_fmadd_ps(_mm512_mul_ps(sin_t, t2), t, t);
  cos_t = _mm512_fmadd_ps(cos_t, t2, _mm512_set1_ps(1.0f));
  // Quadrant k = q mod 4: (cos, sin) = (c, s), (-s, c), (-c, -s), (s, -c).
  const __m512i k = _mm512_and_si512(_mm512_cvtps_epi32(q), _mm512_set1_epi32(3));
  const __mmask16 odd = _mm512_test_epi32_mask(k, _mm512_set1_epi32(1));
  const __mmask16 cos_negative = _mm512_test_epi32_mask(_mm512_add_epi32(k, _mm512_set1_epi32(1)), _mm512_set1_epi32(2));
  const __mmask16 sin_negative = _mm512_test_epi32_mask(k, _mm512_set1_epi32(2));
  c = _mm512_mask_blend_ps(odd, cos_t, sin_t);
  s = _mm512_mask_blend_ps(odd, sin_t, cos_t);
  c = _mm512_mask_sub_ps(c, cos_negative, _mm512_setzero_ps(), c);
  s = _mm512_mask_sub_ps(s, sin_negative, _mm512_setzero_ps(), s);
}

HC_AVX512 void normal_pairs(std::ptrdiff_t pairs, const std::uint64_t* bits, float* out) {
  const __m512i interleave_low = _mm512_setr_epi32(0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7, 23);
  const __m512i interleave_high = _mm512_setr_epi32(8, 24, 9, 25, 10, 26, 11, 27, 12, 28, 13, 29, 14, 30, 15, 31);
  const __m512 scale = _mm512_set1_ps(BoxMuller::kTwoPow24Inverse);
  for (std::ptrdiff_t i = 0; i < pairs; i += 16) {
    const std::ptrdiff_t count = std::min<std::ptrdiff_t>(16, pairs - i);
    const __mmask8 first = static_cast<__mmask8>(count >= 8 ? 0xFF : (1u << count) - 1u);
    const __mmask8 second = static_cast<__mmask8>(count >= 16 ? 0xFF : count <= 8 ? 0 : (1u << (count - 8)) - 1u);
    const __m512i b0 = maskz_loadu_epi64(first, bits + i), b1 = maskz_loadu_epi64(second, bits + i + 8);
    // High and low 24-bit fields of each draw (BoxMuller::high24 / low24), 16 lanes each.
    const __m512i high = _mm512_inserti64x4(_mm512_castsi256_si512(_mm512_cvtepi64_epi32(_mm512_srli_epi64(b0, 40))),
                                            _mm512_cvtepi64_epi32(_mm512_srli_epi64(b1, 40)), 1);
    const __m512i low = _mm512_and_si512(
        _mm512_inserti64x4(_mm512_castsi256_si512(_mm512_cvtepi64_epi32(_mm512_srli_epi64(b0, 8))),
                           _mm512_cvtepi64_epi32(_mm512_srli_epi64(b1, 8)), 1),
        _mm512_set1_epi32(0xFFFFFF));
    const __m512 u1 = _mm512_mul_ps(_mm512_cvtepi32_ps(_mm512_add_epi32(high, _mm512_set1_epi32(1))), scale);
    const __m512 u2 = _mm512_mul_ps(_mm512_cvtepi32_ps(low), scale);
    const __m512 radius = _mm512_sqrt_ps(_mm512_mul_ps(_mm512_set1_ps(-2.0f), log_unit_ps(u1)));
    __m512 c, s;
    cos_sin_turns_ps(u2, c, s);
    c = _mm512_mul_ps(radius, c);
    s = _mm512_mul_ps(radius, s);
    const __mmask16 lanes = tail_mask(2 * count), lanes_high = tail_mask(2 * count - 16 > 0 ? 2 * count - 16 : 0);
    mask_storeu(out + 2 * i, lanes, _mm512_permutex2var_ps(c, interleave_low, s));
    mask_storeu(out + 2 * i + 16, lanes_high, _mm512_permutex2var_ps(c, interleave_high, s));
  }
}

}  // namespace

const KernelSet& avx512_kernels() {
  static const KernelSet set{vector_gemm<Avx512Kernel>, silu_forward, silu_backward, silu,
                             squared_norm, adam, normal_pairs};
  return set;
}

}  // namespace handcentric::policy::kernels
