#pragma once
// Private: the float32 kernels behind Mlp and Adam, one implementation per instruction set
// (generic.cpp: Eigen for the build's target; avx2.cpp; avx512.cpp), chosen at run time by
// the functions at the bottom (dispatch.cpp, kernels.hpp).
//
// Storage is column-major throughout, as in Eigen: element (i, j) of an r x c matrix with
// leading dimension ld is data[i + j * ld]. op(X) is X or X^T as stored.
#include <cstddef>
#include <cstdint>

#include "handcentric/policy/kernels.hpp"

namespace handcentric::policy::kernels {

enum class Op { none, transpose };

/// What happens to C once its sum is complete, while the block of C is still in L1: nothing;
/// SiLU in place (a hidden layer's activation); or the product by SiLU's derivative (the
/// backward pass through that activation).
enum class Epilogue { none, silu, silu_derivative };

/// C (m x n, ldc) = op(A) op(B) + bias 1^T, with op(A) m x k and op(B) k x n; `row_bias` (m
/// floats) may be null. C must not alias A, B or the bias. k = 0 gives C = bias 1^T (or 0).
/// n = 1 with op(A) = A is a matrix-vector product (batch-1 sampling) and has its own kernel.
/// With Epilogue::silu, C = SiLU(Z) for that Z, and `sigmoid` (m x n, lds), when not null,
/// gets sigmoid(Z) (kept for the backward pass).
/// With Epilogue::silu_derivative, C = Z * SiLU'(z) elementwise, SiLU'(z) = s + a (1 - s), from
/// the forward pass's s = `sigmoid` and a = `activation` = SiLU(z) (both m x n, lds, read only).
struct Gemm {
  Op op_a = Op::none, op_b = Op::none;
  int m = 0, n = 0, k = 0;
  const float* a = nullptr;
  int lda = 0;
  const float* b = nullptr;
  int ldb = 0;
  const float* row_bias = nullptr;
  float* c = nullptr;
  int ldc = 0;
  Epilogue epilogue = Epilogue::none;
  float* sigmoid = nullptr;
  int lds = 0;
  const float* activation = nullptr;
};

/// Handles the degenerate shapes (m, n or k <= 0; k = 0 writes C = bias 1^T) and returns
/// true; false for a real product. Every set's gemm starts with it.
bool trivial_gemm(const Gemm& problem);

/// One set's SiLU functions, as KernelSet has them.
struct SiluFunctions {
  void (*forward)(std::ptrdiff_t n, const float* z, float* s, float* a);
  void (*in_place)(std::ptrdiff_t n, float* x);
  void (*backward)(std::ptrdiff_t n, const float* a, const float* s, float* delta);
};

/// Applies problem.epilogue to rows [i0, i0 + rows) of columns [j0, j0 + cols) of C with one
/// set's SiLU functions (Epilogue::silu: `forward` when problem.sigmoid is set, else
/// `in_place`; Epilogue::silu_derivative: `backward`).
void apply_epilogue(const Gemm& problem, int i0, int rows, int j0, int cols, const SiluFunctions& silu);

/// Adam's update of n parameters (adam.hpp) from g = gradient_scale gradient:
/// m = b1 m + (1 - b1) g, v = b2 v + (1 - b2) g^2, p = decay p - step_size m / (sqrt(v) inv_sqrt_bias2 + eps).
struct AdamUpdate {
  std::ptrdiff_t n = 0;
  float* parameters = nullptr;
  const float* gradient = nullptr;
  float gradient_scale = 1;
  float* m = nullptr;
  float* v = nullptr;
  float beta1 = 0, beta2 = 0, step_size = 0, inv_sqrt_bias2 = 0, epsilon = 0, decay = 1;
};

/// exp(x) in the vector sets (Cephes' expf): x = n ln2 + r with n = round(x log2 e) and
/// ln2 = kLn2High + kLn2Low (r exact to float rounding), then
/// exp(r) = 1 + r + r^2 (c0 r^5 + c1 r^4 + ... + c5), relative error ~1e-7, times 2^n.
struct ExpPolynomial {
  static constexpr float kLog2e = 1.44269504088896341f;
  static constexpr float kLn2High = 0.693359375f, kLn2Low = -2.12194440e-4f;
  static constexpr float kC[6] = {1.9875691500e-4f, 1.3981999507e-3f, 8.3334519073e-3f,
                                  4.1665795894e-2f, 1.6666665459e-1f, 5.0000001201e-1f};
};

/// Box-Muller from one 64-bit draw per pair of normals (gaussian.hpp): with the top 24 bits
/// of each 32-bit half, u1 = (hi + 1) 2^-24 in (0, 1] and u2 = lo 2^-24 in [0, 1), both exact
/// in float; r = sqrt(-2 ln u1) (at most sqrt(48 ln 2) = 5.77: the tails beyond 5.77 sigma,
/// probability 8e-9, are cut), and the pair is (r cos 2 pi u2, r sin 2 pi u2).
struct BoxMuller {
  static std::uint32_t high24(std::uint64_t bits) { return static_cast<std::uint32_t>(bits >> 40); }
  static std::uint32_t low24(std::uint64_t bits) { return static_cast<std::uint32_t>(bits >> 8) & 0xFFFFFFu; }
  static constexpr float kTwoPow24Inverse = 0x1.0p-24f;
};

/// The polynomials of the vector Box-Muller (avx2.cpp, avx512.cpp), coefficients highest first.
/// ln m for m in [sqrt(1/2), sqrt(2)): 2 s (1 + s^2/3 + ... + s^8/9), s = (m - 1) / (m + 1).
/// sin t and cos t for |t| <= pi/4 by Taylor: t + t^3 (kSin...), 1 + t^2 (kCos...).
struct BoxMullerPolynomials {
  static constexpr float kLn2 = 0.693147180559945f, kSqrt2 = 1.41421356f;
  static constexpr float kTwoPi = 6.28318530717958648f;
  static constexpr float kLog[4] = {1.0f / 9.0f, 1.0f / 7.0f, 1.0f / 5.0f, 1.0f / 3.0f};
  static constexpr float kSin[4] = {1.0f / 362880.0f, -1.0f / 5040.0f, 1.0f / 120.0f, -1.0f / 6.0f};
  static constexpr float kCos[4] = {1.0f / 40320.0f, -1.0f / 720.0f, 1.0f / 24.0f, -0.5f};
};

/// One instruction set's kernels. SiLU(z) = z s with s = sigmoid(z) = 1 / (1 + exp(-z)).
struct KernelSet {
  void (*gemm)(const Gemm& problem);
  /// s = sigmoid(z), a = z s over n values (training: s is kept for the backward pass); a may be z.
  void (*silu_forward)(std::ptrdiff_t n, const float* z, float* s, float* a);
  /// delta *= SiLU'(z) over n values, from s = sigmoid(z) and a = SiLU(z) = z s:
  /// SiLU'(z) = s (1 + z (1 - s)) = s + a (1 - s), so z itself need not be kept.
  void (*silu_backward)(std::ptrdiff_t n, const float* a, const float* s, float* delta);
  /// x = SiLU(x) in place (inference).
  void (*silu)(std::ptrdiff_t n, float* x);
  /// sum of g_i^2, in double.
  double (*squared_norm)(std::ptrdiff_t n, const float* g);
  void (*adam)(const AdamUpdate& update);
  /// out[2 i], out[2 i + 1] = the BoxMuller pair of bits[i], i < pairs.
  void (*normal_pairs)(std::ptrdiff_t pairs, const std::uint64_t* bits, float* out);
};

const KernelSet& generic_kernels();
const KernelSet& avx2_kernels();    ///< only where HANDCENTRIC_X86_KERNELS is defined
const KernelSet& avx512_kernels();  ///< only where HANDCENTRIC_X86_KERNELS is defined

/// The set for `isa` (which must be supported), and the one in use (kernel_isa()).
const KernelSet& kernels_for(KernelIsa isa);
const KernelSet& active();

}  // namespace handcentric::policy::kernels
