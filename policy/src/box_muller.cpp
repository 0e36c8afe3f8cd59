// Scalar float, with libm's logf, cosf and sinf: a training step of the flow policy draws
// 24 x 256 normals against 225 MFLOP of products, a sample 24 against 6 MFLOP, so the noise is a
// few percent of either (docs/BENCHMARKS.md, section "Policy").
#include "box_muller.hpp"

#include <cmath>
#include <numbers>

namespace handcentric::policy {

void box_muller_pairs(std::ptrdiff_t pairs, const std::uint64_t* bits, float* out) {
  for (std::ptrdiff_t i = 0; i < pairs; ++i) {
    const float u1 =
        static_cast<float>(BoxMuller::high24(bits[i]) + 1) * BoxMuller::kTwoPow24Inverse;
    const float u2 = static_cast<float>(BoxMuller::low24(bits[i])) * BoxMuller::kTwoPow24Inverse;
    const float radius = std::sqrt(-2.0f * std::log(u1));
    const float angle = 2.0f * std::numbers::pi_v<float> * u2;
    out[2 * i] = radius * std::cos(angle);
    out[2 * i + 1] = radius * std::sin(angle);
  }
}

}  // namespace handcentric::policy
