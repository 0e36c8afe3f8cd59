// Private, per target: the optimizer's kernels of KernelSet, the gradient's squared norm (for
// clipping) and Adam's update (kernel_set.hpp, AdamUpdate).

#include <cstddef>

#include <hwy/highway.h>

#include "kernels/kernel_set.hpp"

HWY_BEFORE_NAMESPACE();
namespace handcentric::policy::kernels::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

/// sum of g_i^2, in double: half a vector of floats at a time, widened.
inline double SquaredNorm(std::ptrdiff_t n, const float* g) {
  const hn::ScalableTag<double> dd;
  const hn::Rebind<float, decltype(dd)> df;  // as many floats as dd has doubles
  auto sum0 = hn::Zero(dd), sum1 = hn::Zero(dd);
  std::ptrdiff_t i = 0;
  constexpr std::ptrdiff_t kLanes = static_cast<std::ptrdiff_t>(hn::MaxLanes(decltype(dd)()));
  for (; i + 2 * kLanes <= n; i += 2 * kLanes) {  // two chains of additions
    const auto g0 = hn::PromoteTo(dd, hn::LoadU(df, g + i)),
               g1 = hn::PromoteTo(dd, hn::LoadU(df, g + i + kLanes));
    sum0 = hn::MulAdd(g0, g0, sum0);
    sum1 = hn::MulAdd(g1, g1, sum1);
  }
  ForEachVector(df, n - i, [&](std::ptrdiff_t j, std::size_t count) HWY_ATTR {
    const auto gj = hn::PromoteTo(dd, LoadPart(df, g + i + j, count));
    sum0 = hn::MulAdd(gj, gj, sum0);
  });
  return hn::GetLane(hn::SumOfLanes(dd, hn::Add(sum0, sum1)));
}

inline void Adam(const AdamUpdate& u) {
  const hn::ScalableTag<float> d;
  const auto b1 = hn::Set(d, u.beta1), c1 = hn::Set(d, 1.0f - u.beta1);
  const auto b2 = hn::Set(d, u.beta2), c2 = hn::Set(d, 1.0f - u.beta2);
  const auto step = hn::Set(d, u.step_size), scale = hn::Set(d, u.inv_sqrt_bias2);
  const auto eps = hn::Set(d, u.epsilon), decay = hn::Set(d, u.decay);
  const auto gradient_scale = hn::Set(d, u.gradient_scale);
  const bool decays = u.decay != 1.0f;
  ForEachVector(d, u.n, [&](std::ptrdiff_t i, std::size_t count) HWY_ATTR {
    const auto g = hn::Mul(LoadPart(d, u.gradient + i, count), gradient_scale);
    const auto m = hn::MulAdd(b1, LoadPart(d, u.m + i, count), hn::Mul(c1, g));
    const auto v = hn::MulAdd(b2, LoadPart(d, u.v + i, count), hn::Mul(c2, hn::Mul(g, g)));
    auto p = LoadPart(d, u.parameters + i, count);
    if (decays) p = hn::Mul(p, decay);
    p = hn::Sub(p, hn::Div(hn::Mul(step, m), hn::MulAdd(hn::Sqrt(v), scale, eps)));
    StorePart(d, m, u.m + i, count);
    StorePart(d, v, u.v + i, count);
    StorePart(d, p, u.parameters + i, count);
  });
}

}  // namespace handcentric::policy::kernels::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();
