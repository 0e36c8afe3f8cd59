// AVX2 + FMA kernels (see avx512.cpp for why every vector function carries the target
// attribute and the translation unit does not). avx2_kernels() is only used after
// kernel_isa_supported(KernelIsa::avx2) said yes.
#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>

#include "asan_lanes.hpp"
#include "kernel_set.hpp"
#include "pack.hpp"

#define HC_AVX2 __attribute__((target("avx2,fma")))

namespace handcentric::policy::kernels {
namespace {

// The masked accesses, through asan_lanes.hpp's check (empty without ASan); lane i is enabled
// when the sign bit of lane i of `mask` is set.
HC_AVX2 inline __attribute__((always_inline)) __m256 maskload(const float* p, __m256i mask) {
  check_lanes(p, static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(mask))), sizeof(float), false);
  return _mm256_maskload_ps(p, mask);
}
HC_AVX2 inline __attribute__((always_inline)) void maskstore(float* p, __m256i mask, __m256 value) {
  check_lanes(p, static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(mask))), sizeof(float), true);
  _mm256_maskstore_ps(p, mask, value);
}

HC_AVX2 void silu_forward(std::ptrdiff_t n, const float* z, float* s, float* a);
HC_AVX2 void silu(std::ptrdiff_t n, float* x);
HC_AVX2 void silu_backward(std::ptrdiff_t n, const float* a, const float* s, float* delta);

// One narrow product C(rows, 0:N) = A(rows, 0:k) op(B)(0:k, 0:N) (+ bias) with N x V accumulators:
// the contract of pack.hpp's narrow loop nest ("Narrow products").
template <int N, int V>
HC_AVX2 void narrow_product(int shift, int rows, int k, const float* a, long lda, const float* b, long b_step,
                            long b_stride, const float* bias, float* c, long ldc) {
  const int lanes = shift + rows;  // in 8 (V - 1) + 1 .. 8 V
  alignas(32) int head_lanes[8], tail_lanes[8];
  for (int i = 0; i < 8; ++i) {
    head_lanes[i] = i >= shift && (V > 1 || i < lanes) ? -1 : 0;
    tail_lanes[i] = 8 * (V - 1) + i < lanes && (V > 1 || i >= shift) ? -1 : 0;
  }
  const __m256i head = _mm256_load_si256(reinterpret_cast<const __m256i*>(head_lanes));
  const __m256i tail = _mm256_load_si256(reinterpret_cast<const __m256i*>(tail_lanes));
  a -= shift;
  c -= shift;
  if (bias != nullptr) bias -= shift;
  const auto load = [&](const float* p, int v) HC_AVX2 {
    return v == 0 ? maskload(p, head) : v + 1 == V ? maskload(p, tail) : _mm256_loadu_ps(p);
  };
  __m256 acc[N][V];
  #pragma GCC unroll 16
  for (int v = 0; v < V; ++v) {
    const __m256 start = bias != nullptr ? load(bias + 8 * v, v) : _mm256_setzero_ps();
    #pragma GCC unroll 16
    for (int j = 0; j < N; ++j) acc[j][v] = start;
  }
  for (int p = 0; p < k; ++p) {
    const float* column = a + p * lda;
    const float* b_row = b + p * b_step;
    #pragma GCC unroll 16
    for (int v = 0; v < V; ++v) {
      const __m256 a_v = load(column + 8 * v, v);
      #pragma GCC unroll 16
      for (int j = 0; j < N; ++j) acc[j][v] = _mm256_fmadd_ps(a_v, _mm256_broadcast_ss(b_row + j * b_stride), acc[j][v]);
    }
  }
  #pragma GCC unroll 16
  for (int j = 0; j < N; ++j) {
    float* cj = c + j * ldc;
    #pragma GCC unroll 16
    for (int v = 0; v < V; ++v) {
      if (v == 0) {
        maskstore(cj, head, acc[j][0]);
      } else if (v + 1 == V) {
        maskstore(cj + 8 * v, tail, acc[j][v]);
      } else {
        _mm256_storeu_ps(cj + 8 * v, acc[j][v]);
      }
    }
  }
}

// C tile of 16 x 6 = 12 ymm accumulators; per k: 2 loads of A, 6 broadcasts of B, 12 FMAs.
struct Avx2Kernel {
  static constexpr int MR = 16, NR = 6;
  static constexpr int kNarrowLanes = 8, kNarrowAccumulators = 12, kNarrowGroup = 4;
  template <int N, int V>
  static constexpr auto narrow_block = &narrow_product<N, V>;
  static constexpr SiluFunctions kSilu{silu_forward, silu, silu_backward};
  static constexpr auto pack_a = kernels::pack_a<MR>;

  template <BLayout layout>
  HC_AVX2 static void tile(int kc, const float* a, const float* b, int ldb, float* c, int ldc, bool accumulate,
                           const float* bias) {
    __m256 acc[NR][2];
    #pragma GCC unroll 32
    for (int j = 0; j < NR; ++j) acc[j][0] = acc[j][1] = _mm256_setzero_ps();
    for (int p = 0; p < kc; ++p) {
      const __m256 a0 = _mm256_load_ps(a), a1 = _mm256_load_ps(a + 8);
      #pragma GCC unroll 32
      for (int j = 0; j < NR; ++j) {
        const __m256 bj = _mm256_broadcast_ss(layout == BLayout::columns ? b + j * static_cast<long>(ldb) : b + j);
        acc[j][0] = _mm256_fmadd_ps(a0, bj, acc[j][0]);
        acc[j][1] = _mm256_fmadd_ps(a1, bj, acc[j][1]);
      }
      a += MR;
      b += layout == BLayout::packed ? NR : layout == BLayout::rows ? ldb : 1;
    }
    __m256 add0 = _mm256_setzero_ps(), add1 = _mm256_setzero_ps();
    if (!accumulate && bias != nullptr) {
      add0 = _mm256_loadu_ps(bias);
      add1 = _mm256_loadu_ps(bias + 8);
    }
    #pragma GCC unroll 32
    for (int j = 0; j < NR; ++j) {
      float* cj = c + static_cast<long>(j) * ldc;
      if (accumulate) {
        add0 = _mm256_loadu_ps(cj);
        add1 = _mm256_loadu_ps(cj + 8);
      }
      _mm256_storeu_ps(cj, _mm256_add_ps(acc[j][0], add0));
      _mm256_storeu_ps(cj + 8, _mm256_add_ps(acc[j][1], add1));
    }
  }
};

// exp(x) by ExpPolynomial (kernel_set.hpp), 2^n built in the exponent bits; x is
// clamped to [-87.3, 88.7] so that n + 127 stays a normal exponent.
HC_AVX2 __m256 exp_ps(__m256 x) {
  x = _mm256_min_ps(_mm256_max_ps(x, _mm256_set1_ps(-87.3f)), _mm256_set1_ps(88.7f));
  const __m256 n = _mm256_round_ps(_mm256_mul_ps(x, _mm256_set1_ps(ExpPolynomial::kLog2e)),
                                   _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
  __m256 r = _mm256_fnmadd_ps(n, _mm256_set1_ps(ExpPolynomial::kLn2High), x);
  r = _mm256_fnmadd_ps(n, _mm256_set1_ps(ExpPolynomial::kLn2Low), r);
  __m256 p = _mm256_set1_ps(ExpPolynomial::kC[0]);
#pragma GCC unroll 5
  for (int i = 1; i < 6; ++i) p = _mm256_fmadd_ps(p, r, _mm256_set1_ps(ExpPolynomial::kC[i]));
  p = _mm256_fmadd_ps(p, _mm256_mul_ps(r, r), _mm256_add_ps(r, _mm256_set1_ps(1.0f)));
  const __m256i exponent = _mm256_slli_epi32(_mm256_add_epi32(_mm256_cvtps_epi32(n), _mm256_set1_epi32(127)), 23);
  return _mm256_mul_ps(p, _mm256_castsi256_ps(exponent));
}

HC_AVX2 __m256 sigmoid_ps(__m256 z) {
  const __m256 one = _mm256_set1_ps(1.0f);
  return _mm256_div_ps(one, _mm256_add_ps(one, exp_ps(_mm256_sub_ps(_mm256_setzero_ps(), z))));
}

// The tails (n mod 8 values) go through a zero-padded 8-float buffer.
template <typename Body>
HC_AVX2 void for_blocks(std::ptrdiff_t n, Body&& body) {
  std::ptrdiff_t i = 0;
  for (; i + 8 <= n; i += 8) body(i, 8);
  if (i < n) body(i, static_cast<int>(n - i));
}

HC_AVX2 __m256 load(const float* p, int count) {
  if (count == 8) return _mm256_loadu_ps(p);
  alignas(32) float buffer[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  for (int i = 0; i < count; ++i) buffer[i] = p[i];
  return _mm256_load_ps(buffer);
}

HC_AVX2 void store(float* p, __m256 x, int count) {
  if (count == 8) {
    _mm256_storeu_ps(p, x);
    return;
  }
  alignas(32) float buffer[8];
  _mm256_store_ps(buffer, x);
  for (int i = 0; i < count; ++i) p[i] = buffer[i];
}

HC_AVX2 void silu_forward(std::ptrdiff_t n, const float* z, float* s, float* a) {
  for_blocks(n, [&](std::ptrdiff_t i, int count) HC_AVX2 {
    const __m256 zi = load(z + i, count), si = sigmoid_ps(zi);
    store(s + i, si, count);
    store(a + i, _mm256_mul_ps(zi, si), count);
  });
}

HC_AVX2 void silu_backward(std::ptrdiff_t n, const float* a, const float* s, float* delta) {
  for_blocks(n, [&](std::ptrdiff_t i, int count) HC_AVX2 {
    const __m256 one = _mm256_set1_ps(1.0f);
    const __m256 ai = load(a + i, count), si = load(s + i, count);
    const __m256 derivative = _mm256_fmadd_ps(ai, _mm256_sub_ps(one, si), si);  // s + a (1 - s)
    store(delta + i, _mm256_mul_ps(load(delta + i, count), derivative), count);
  });
}

HC_AVX2 void silu(std::ptrdiff_t n, float* x) {
  for_blocks(n, [&](std::ptrdiff_t i, int count) HC_AVX2 {
    const __m256 xi = load(x + i, count);
    store(x + i, _mm256_mul_ps(xi, sigmoid_ps(xi)), count);
  });
}

HC_AVX2 double squared_norm(std::ptrdiff_t n, const float* g) {
  __m256d sum0 = _mm256_setzero_pd(), sum1 = _mm256_setzero_pd();
  for_blocks(n, [&](std::ptrdiff_t i, int count) HC_AVX2 {
    const __m256 gi = load(g + i, count);
    const __m256d lo = _mm256_cvtps_pd(_mm256_castps256_ps128(gi)), hi = _mm256_cvtps_pd(_mm256_extractf128_ps(gi, 1));
    sum0 = _mm256_fmadd_pd(lo, lo, sum0);
    sum1 = _mm256_fmadd_pd(hi, hi, sum1);
  });
  alignas(32) double lanes[4];
  _mm256_store_pd(lanes, _mm256_add_pd(sum0, sum1));
  return (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]);
}

HC_AVX2 void adam(const AdamUpdate& u) {
  for_blocks(u.n, [&](std::ptrdiff_t i, int count) HC_AVX2 {
    const __m256 g = _mm256_mul_ps(load(u.gradient + i, count), _mm256_set1_ps(u.gradient_scale));
    const __m256 m = _mm256_fmadd_ps(_mm256_set1_ps(u.beta1), load(u.m + i, count),
                                     _mm256_mul_ps(_mm256_set1_ps(1.0f - u.beta1), g));
    const __m256 v = _mm256_fmadd_ps(_mm256_set1_ps(u.beta2), load(u.v + i, count),
                                     _mm256_mul_ps(_mm256_set1_ps(1.0f - u.beta2), _mm256_mul_ps(g, g)));
    __m256 p = load(u.parameters + i, count);
    if (u.decay != 1.0f) p = _mm256_mul_ps(p, _mm256_set1_ps(u.decay));
    const __m256 denominator = _mm256_fmadd_ps(_mm256_sqrt_ps(v), _mm256_set1_ps(u.inv_sqrt_bias2), _mm256_set1_ps(u.epsilon));
    p = _mm256_sub_ps(p, _mm256_div_ps(_mm256_mul_ps(_mm256_set1_ps(u.step_size), m), denominator));
    store(u.m + i, m, count);
    store(u.v + i, v, count);
    store(u.parameters + i, p, count);
  });
}

// ln x for x in [2^-24, 1], as in avx512.cpp, with the exponent and mantissa from the bits.
HC_AVX2 __m256 log_unit_ps(__m256 x) {
  const __m256i bits = _mm256_castps_si256(x);
  __m256 e = _mm256_cvtepi32_ps(_mm256_sub_epi32(_mm256_srli_epi32(bits, 23), _mm256_set1_epi32(127)));
  __m256 m = _mm256_castsi256_ps(_mm256_or_si256(_mm256_and_si256(bits, _mm256_set1_epi32(0x007FFFFF)),
                                                 _mm256_set1_epi32(0x3F800000)));  // [1, 2)
  const __m256 big = _mm256_cmp_ps(m, _mm256_set1_ps(BoxMullerPolynomials::kSqrt2), _CMP_GT_OQ);
  m = _mm256_blendv_ps(m, _mm256_mul_ps(m, _mm256_set1_ps(0.5f)), big);
  e = _mm256_add_ps(e, _mm256_and_ps(big, _mm256_set1_ps(1.0f)));
  const __m256 one = _mm256_set1_ps(1.0f);
  const __m256 s = _mm256_div_ps(_mm256_sub_ps(m, one), _mm256_add_ps(m, one)), s2 = _mm256_mul_ps(s, s);
  __m256 series = _mm256_set1_ps(BoxMullerPolynomials::kLog[0]);
  for (int i = 1; i < 4; ++i) series = _mm256_fmadd_ps(series, s2, _mm256_set1_ps(BoxMullerPolynomials::kLog[i]));
  series = _mm256_fmadd_ps(series, s2, one);
  return _mm256_fmadd_ps(e, _mm256_set1_ps(BoxMullerPolynomials::kLn2), _mm256_mul_ps(_mm256_add_ps(s, s), series));
}

// cos and sin of 2 pi u for u in [0, 1), as in avx512.cpp.
HC_AVX2 void cos_sin_turns_ps(__m256 u, __m256& c, __m256& s) {
  const __m256 q = _mm256_round_ps(_mm256_mul_ps(u, _mm256_set1_ps(4.0f)), _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC);
  const __m256 t = _mm256_mul_ps(_mm256_fnmadd_ps(q, _mm256_set1_ps(0.25f), u), _mm256_set1_ps(BoxMullerPolynomials::kTwoPi));
  const __m256 t2 = _mm256_mul_ps(t, t);
  __m256 sin_t = _mm256_set1_ps(BoxMullerPolynomials::kSin[0]), cos_t = _mm256_set1_ps(BoxMullerPolynomials::kCos[0]);
  for (int i = 1; i < 4; ++i) {
    sin_t = _mm256_fmadd_ps(sin_t, t2, _mm256_set1_ps(BoxMullerPolynomials::kSin[i]));
    cos_t = _mm256_fmadd_ps(cos_t, t2, _mm256_set1_ps(BoxMullerPolynomials::kCos[i]));
  }
  sin_t = _mm256_fmadd_ps(_mm256_mul_ps(sin_t, t2), t, t);
  cos_t = _mm256_fmadd_ps(cos_t, t2, _mm256_set1_ps(1.0f));
  // Quadrant k = q mod 4: (cos, sin) = (c, s), (-s, c), (-c, -s), (s, -c); signs by xor.
  const __m256i k = _mm256_and_si256(_mm256_cvtps_epi32(q), _mm256_set1_epi32(3));
  const __m256 odd = _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(k, _mm256_set1_epi32(1)), _mm256_set1_epi32(1)));
  const __m256i sign = _mm256_set1_epi32(static_cast<int>(0x80000000u));
  const __m256i cos_sign = _mm256_slli_epi32(_mm256_and_si256(_mm256_add_epi32(k, _mm256_set1_epi32(1)), _mm256_set1_epi32(2)), 30);
  const __m256i sin_sign = _mm256_slli_epi32(_mm256_and_si256(k, _mm256_set1_epi32(2)), 30);
  c = _mm256_xor_ps(_mm256_blendv_ps(cos_t, sin_t, odd), _mm256_castsi256_ps(_mm256_and_si256(cos_sign, sign)));
  s = _mm256_xor_ps(_mm256_blendv_ps(sin_t, cos_t, odd), _mm256_castsi256_ps(_mm256_and_si256(sin_sign, sign)));
}

HC_AVX2 void normal_pairs(std::ptrdiff_t pairs, const std::uint64_t* bits, float* out) {
  for (std::ptrdiff_t i = 0; i < pairs; i += 8) {
    const int count = static_cast<int>(std::min<std::ptrdiff_t>(8, pairs - i));
    alignas(32) std::int32_t high[8] = {0, 0, 0, 0, 0, 0, 0, 0}, low[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    for (int k = 0; k < count; ++k) {
      high[k] = static_cast<std::int32_t>(BoxMuller::high24(bits[i + k]));
      low[k] = static_cast<std::int32_t>(BoxMuller::low24(bits[i + k]));
    }
    const __m256 scale = _mm256_set1_ps(BoxMuller::kTwoPow24Inverse);
    const __m256 u1 = _mm256_mul_ps(
        _mm256_cvtepi32_ps(_mm256_add_epi32(_mm256_load_si256(reinterpret_cast<const __m256i*>(high)), _mm256_set1_epi32(1))),
        scale);
    const __m256 u2 = _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_load_si256(reinterpret_cast<const __m256i*>(low))), scale);
    const __m256 radius = _mm256_sqrt_ps(_mm256_mul_ps(_mm256_set1_ps(-2.0f), log_unit_ps(u1)));
    __m256 c, s;
    cos_sin_turns_ps(u2, c, s);
    c = _mm256_mul_ps(radius, c);
    s = _mm256_mul_ps(radius, s);
    // Interleave (c0, s0, c1, s1, ...): unpack within 128-bit lanes, then order the lanes.
    const __m256 lo = _mm256_unpacklo_ps(c, s), hi = _mm256_unpackhi_ps(c, s);
    alignas(32) float pairs_out[16];
    _mm256_store_ps(pairs_out, _mm256_permute2f128_ps(lo, hi, 0x20));
    _mm256_store_ps(pairs_out + 8, _mm256_permute2f128_ps(lo, hi, 0x31));
    for (int k = 0; k < 2 * count; ++k) out[2 * i + k] = pairs_out[k];
  }
}

}  // namespace

const KernelSet& avx2_kernels() {
  static const KernelSet set{vector_gemm<Avx2Kernel>, silu_forward, silu_backward, silu, squared_norm, adam, normal_pairs};
  return set;
}

}  // namespace handcentric::policy::kernels
