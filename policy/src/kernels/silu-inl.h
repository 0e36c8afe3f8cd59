// Private, per target: exp, sigmoid and the three SiLU kernels of KernelSet (kernel_set.hpp).

#include <cstddef>

#include <hwy/highway.h>

#include "kernels/kernel_set.hpp"

HWY_BEFORE_NAMESPACE();
namespace handcentric::policy::kernels::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

/// exp(x) by ExpPolynomial (kernel_set.hpp), 2^n built in the exponent bits. x is clamped to
/// [-87.3, 88.7], where n + 127 stays a normal exponent: exp(-87.3) = 1.2e-38 is as good as 0
/// and exp(88.7) = 3.3e38 as good as +inf for the sigmoid, the only caller.
template <class D, class V = hn::Vec<D>>
HWY_INLINE V Exp(D d, V x) {
  const hn::RebindToSigned<D> di;
  x = hn::Min(hn::Max(x, hn::Set(d, -87.3f)), hn::Set(d, 88.7f));
  const V n = hn::Round(hn::Mul(x, hn::Set(d, ExpPolynomial::kLog2e)));
  V r = hn::NegMulAdd(n, hn::Set(d, ExpPolynomial::kLn2High), x);
  r = hn::NegMulAdd(n, hn::Set(d, ExpPolynomial::kLn2Low), r);
  V p = hn::Set(d, ExpPolynomial::kC[0]);
#pragma GCC unroll 5
  for (int i = 1; i < 6; ++i) p = hn::MulAdd(p, r, hn::Set(d, ExpPolynomial::kC[i]));
  p = hn::MulAdd(p, hn::Mul(r, r), hn::Add(r, hn::Set(d, 1.0f)));
  const auto exponent = hn::ShiftLeft<23>(hn::Add(hn::ConvertTo(di, n), hn::Set(di, 127)));
  return hn::Mul(p, hn::BitCast(d, exponent));
}

/// sigmoid(z) = 1 / (1 + exp(-z)), by a true division: it is a small part of the products'
/// epilogue, and an approximate reciprocal would differ between targets.
template <class D, class V = hn::Vec<D>>
HWY_INLINE V Sigmoid(D d, V z) {
  const V one = hn::Set(d, 1.0f);
  return hn::Div(one, hn::Add(one, Exp(d, hn::Neg(z))));
}

inline void SiluForward(std::ptrdiff_t n, const float* z, float* s, float* a) {
  const hn::ScalableTag<float> d;
  ForEachVector(d, n, [&](std::ptrdiff_t i, std::size_t count) HWY_ATTR {
    const auto zi = LoadPart(d, z + i, count), si = Sigmoid(d, zi);
    StorePart(d, si, s + i, count);
    StorePart(d, hn::Mul(zi, si), a + i, count);
  });
}

inline void SiluBackward(std::ptrdiff_t n, const float* a, const float* s, float* delta) {
  const hn::ScalableTag<float> d;
  ForEachVector(d, n, [&](std::ptrdiff_t i, std::size_t count) HWY_ATTR {
    const auto ai = LoadPart(d, a + i, count), si = LoadPart(d, s + i, count);
    const auto derivative = hn::MulAdd(ai, hn::Sub(hn::Set(d, 1.0f), si), si);  // s + a (1 - s)
    StorePart(d, hn::Mul(LoadPart(d, delta + i, count), derivative), delta + i, count);
  });
}

inline void SiluInPlace(std::ptrdiff_t n, float* x) {
  const hn::ScalableTag<float> d;
  ForEachVector(d, n, [&](std::ptrdiff_t i, std::size_t count) HWY_ATTR {
    const auto xi = LoadPart(d, x + i, count);
    StorePart(d, hn::Mul(xi, Sigmoid(d, xi)), x + i, count);
  });
}

}  // namespace handcentric::policy::kernels::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();
