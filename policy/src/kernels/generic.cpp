// The portable kernel set: Eigen, compiled for the build's target (SSE2 on plain x86-64).
// It is also the reference the vector sets are tested against (tests/policy/test_kernels.cpp).
#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "kernel_set.hpp"

namespace handcentric::policy::kernels {
namespace {

using ArrayMap = Eigen::Map<Eigen::ArrayXf>;
using ConstArrayMap = Eigen::Map<const Eigen::ArrayXf>;

void silu_forward(std::ptrdiff_t n, const float* z, float* s, float* a);
void silu(std::ptrdiff_t n, float* x);
void silu_backward(std::ptrdiff_t n, const float* a, const float* s, float* delta);

void product(const Gemm& g);

void gemm(const Gemm& g) {
  product(g);
  apply_epilogue(g, 0, g.m, 0, g.n, {silu_forward, silu, silu_backward});
}

void product(const Gemm& g) {
  if (trivial_gemm(g)) return;
  using Map = Eigen::Map<const Eigen::MatrixXf, 0, Eigen::OuterStride<>>;
  const int a_rows = g.op_a == Op::none ? g.m : g.k, a_cols = g.op_a == Op::none ? g.k : g.m;
  const int b_rows = g.op_b == Op::none ? g.k : g.n, b_cols = g.op_b == Op::none ? g.n : g.k;
  const Map a(g.a, a_rows, a_cols, Eigen::OuterStride<>(g.lda));
  const Map b(g.b, b_rows, b_cols, Eigen::OuterStride<>(g.ldb));
  Eigen::Map<Eigen::MatrixXf, 0, Eigen::OuterStride<>> c(g.c, g.m, g.n, Eigen::OuterStride<>(g.ldc));
  if (g.op_a == Op::none && g.op_b == Op::none) {
    c.noalias() = a * b;
  } else if (g.op_a == Op::none) {
    c.noalias() = a * b.transpose();
  } else if (g.op_b == Op::none) {
    c.noalias() = a.transpose() * b;
  } else {
    c.noalias() = a.transpose() * b.transpose();
  }
  if (g.row_bias != nullptr) c.colwise() += Eigen::Map<const Eigen::VectorXf>(g.row_bias, g.m);
}

void silu_forward(std::ptrdiff_t n, const float* z, float* s, float* a) {
  ArrayMap ss(s, n);
  ss = 1.0f / (1.0f + (-ConstArrayMap(z, n)).exp());
  ArrayMap(a, n) = ConstArrayMap(z, n) * ss;  // a may be z: s is computed first
}

void silu_backward(std::ptrdiff_t n, const float* a, const float* s, float* delta) {
  const ConstArrayMap aa(a, n), ss(s, n);
  ArrayMap(delta, n) *= ss + aa * (1.0f - ss);
}

void silu(std::ptrdiff_t n, float* x) {
  ArrayMap xx(x, n);
  xx = xx / (1.0f + (-xx).exp());
}

double squared_norm(std::ptrdiff_t n, const float* g) {
  return Eigen::Map<const Eigen::VectorXf>(g, n).cast<double>().squaredNorm();
}

void adam(const AdamUpdate& u) {
  ArrayMap p(u.parameters, u.n), m(u.m, u.n), v(u.v, u.n);
  const ConstArrayMap gradient(u.gradient, u.n);
  const auto g = gradient * u.gradient_scale;
  m = u.beta1 * m + (1.0f - u.beta1) * g;
  v = u.beta2 * v + (1.0f - u.beta2) * g.square();
  if (u.decay != 1.0f) p *= u.decay;
  p -= u.step_size * m / (v.sqrt() * u.inv_sqrt_bias2 + u.epsilon);
}

void normal_pairs(std::ptrdiff_t pairs, const std::uint64_t* bits, float* out) {
  for (std::ptrdiff_t i = 0; i < pairs; ++i) {
    const float u1 = static_cast<float>(BoxMuller::high24(bits[i]) + 1) * BoxMuller::kTwoPow24Inverse;
    const float u2 = static_cast<float>(BoxMuller::low24(bits[i])) * BoxMuller::kTwoPow24Inverse;
    const float radius = std::sqrt(-2.0f * std::log(u1));
    const float angle = 2.0f * std::numbers::pi_v<float> * u2;
    out[2 * i] = radius * std::cos(angle);
    out[2 * i + 1] = radius * std::sin(angle);
  }
}

}  // namespace

const KernelSet& generic_kernels() {
  static const KernelSet set{gemm, silu_forward, silu_backward, silu, squared_norm, adam, normal_pairs};
  return set;
}

}  // namespace handcentric::policy::kernels
