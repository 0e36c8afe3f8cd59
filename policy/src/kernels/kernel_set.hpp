#pragma once
// Private: the float32 kernels behind Mlp and Adam, written once on Google Highway and compiled
// for several targets (kernels.cpp), one KernelSet per target, chosen at run time by the
// functions at the bottom (dispatch.cpp, kernels.hpp).
//
// Storage is column-major throughout, as in Eigen: element (i, j) of an r x c matrix with
// leading dimension ld is data[i + j * ld]. op(X) is X or X^T as stored.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "box_muller.hpp"
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
/// `a_row_sums` (m floats), when not null, gets the sums of op(A)'s rows, sum_p op(A)(i, p), each
/// added from 0 in the order p = 0, 1, ..., k - 1: the bits of the product op(A) 1 on the narrow
/// kernel (db = delta 1, a bias gradient). With op(A) = A the blocked product adds them up while
/// it packs A (a weight gradient delta x^T reads delta once for both).
/// `accumulate` (no bias, Epilogue::none): C += op(A) op(B) instead, and the row sums are added
/// to too: a product over k split into calls, k0 .. k1 then k1 .. k2, gives the bits of one call
/// over k0 .. k2 when k1 - k0 is a multiple of the blocked nest's k block (kProductKBlock) and
/// n > 16 (one narrow product, n <= 16, sums the whole k in one pass).
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
  float* a_row_sums = nullptr;
  bool accumulate = false;
};

/// A product whose op(B) is read in place through offsets: op(B)(p, j) =
/// product.b[b_row_offsets[p] + b_column_offsets[j]] (k row offsets, n column offsets;
/// product.op_b and ldb are not used). A convolution's patch matrix is such an op(B) over a
/// zero-padded image (an implicit im2col), so the layer needs no patch matrix. The rest is
/// Gemm's contract, and C (with its epilogue and row sums) gets the bits gemm gives on that op(B)
/// stored as a matrix.
struct OffsetGemm {
  Gemm product;
  const long* b_row_offsets = nullptr;
  const long* b_column_offsets = nullptr;
};

/// The k block of the blocked products (gemm.hpp, Blocking::KC).
constexpr int kProductKBlock = 256;
/// Products of at most this many columns run on the narrow kernels (gemm.hpp), which start each
/// sum from the bias rather than adding it at the end: other bits than the blocked products'.
constexpr int kNarrowMax = 16;

/// The filters of a PixelConv: one vector of each output pixel's filters on AVX2, half of one
/// on AVX-512 (the image encoder's first layer).
constexpr int kPixelConvFilters = 8;

/// The forward product of a convolution of kPixelConvFilters filters, C = SiLU(W P + b 1^T),
/// with the output pixels in the vector lanes and the 8 filters' weights broadcast: the offset
/// product puts the filters in the lanes, which fill half of an AVX-512 vector. (On the other
/// targets, whose vectors 8 filters fill, it is the offset product.) P (K x N) is read
/// in place, P(p, j) = input[patch_offsets[p] + pixel_offsets[j]], and the pixels of one output
/// row must be consecutive floats of the input: pixel_offsets[r width + x] = pixel_offsets[r width]
/// + x (a channels-first map whose padded rows are stored by column phase, conv_encoder.cpp; only
/// each row's first offset is read). W is kPixelConvFilters x K (ld kPixelConvFilters) and the
/// bias is not null. C and `sigmoid` are kPixelConvFilters x N with ld kPixelConvFilters, each
/// pixel's filters together as the encoder stores its maps. For N > kNarrowMax they get the bits
/// offset_gemm gives on the same product with Epilogue::silu (each sum in the same order, blocked
/// by kProductKBlock in k the same way).
struct PixelConv {
  int k = 0;
  int rows = 0, width = 0;  ///< N = rows width: output rows (samples x height) of `width` pixels
  const float* weights = nullptr;
  const float* bias = nullptr;
  const float* input = nullptr;
  const long* patch_offsets = nullptr;
  const long* pixel_offsets = nullptr;
  float* c = nullptr;
  float* sigmoid = nullptr;
};

/// The weight gradient of a PixelConv: dW = delta P^T (kPixelConvFilters x K, ld
/// kPixelConvFilters, as PixelConv's W) and db = delta 1, with P read as PixelConv reads it (the
/// pixels of one output row consecutive floats of the input; only each row's first offset is
/// read) and delta kPixelConvFilters x N (ld kPixelConvFilters, each pixel's filters together, as
/// the encoder stores a map's gradient). dW and db are written, not accumulated. On AVX-512 the
/// pixels go in the lanes and each sum is split over the lanes and over chunks of rows, added up
/// at the end: not offset_gemm's order of the terms, so other bits than its product (float sums
/// of the same terms, as accurate). On the other targets it is offset_gemm on delta and P^T with
/// a_row_sums = db, that product's bits.
struct PixelConvGradient {
  int k = 0;
  int rows = 0, width = 0;  ///< N = rows width, as PixelConv
  const float* input = nullptr;
  const long* patch_offsets = nullptr;
  const long* pixel_offsets = nullptr;
  const float* delta = nullptr;
  float* d_weights = nullptr;
  float* d_bias = nullptr;
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
void apply_epilogue(const Gemm& problem, int i0, int rows, int j0, int cols,
                    const SiluFunctions& silu);

/// Adam's update of n parameters (adam.hpp) from g = gradient_scale gradient:
/// m = b1 m + (1 - b1) g, v = b2 v + (1 - b2) g^2,
/// p = decay p - step_size m / (sqrt(v) inv_sqrt_bias2 + eps).
struct AdamUpdate {
  std::ptrdiff_t n = 0;
  float* parameters = nullptr;
  const float* gradient = nullptr;
  float gradient_scale = 1;
  float* m = nullptr;
  float* v = nullptr;
  float beta1 = 0, beta2 = 0, step_size = 0, inv_sqrt_bias2 = 0, epsilon = 0, decay = 1;
};

/// exp(x) in the kernels (silu-inl.h; Cephes' expf): x = n ln2 + r with n = round(x log2 e) and
/// ln2 = kLn2High + kLn2Low (r exact to float rounding), then
/// exp(r) = 1 + r + r^2 (c0 r^5 + c1 r^4 + ... + c5), relative error ~1e-7, times 2^n.
struct ExpPolynomial {
  static constexpr float kLog2e = 1.44269504088896341f;
  static constexpr float kLn2High = 0.693359375f, kLn2Low = -2.12194440e-4f;
  static constexpr float kC[6] = {1.9875691500e-4f, 1.3981999507e-3f, 8.3334519073e-3f,
                                  4.1665795894e-2f, 1.6666665459e-1f, 5.0000001201e-1f};
};

/// The patches of a 2D convolution over a batch of images (conv2d.hpp). Pixel (c, y, x) of
/// sample b is image[b sample_stride + c channel_stride + y row_stride + x column_stride], so one
/// function reads both the encoder's input (channels, height, width) and its hidden maps (height,
/// width, channels; channel_stride 1). Output pixel (oy, ox) sees input rows
/// oy stride - padding + ky and columns ox stride - padding + kx, ky, kx < kernel; rows and
/// columns outside the image are zeros (the padding).
/// The patch matrix is K x N, column-major: K = kernel^2 channels in the order (ky, kx, c), c
/// fastest; N = batch out_height out_width in the order (b, oy, ox), ox fastest.
struct ConvPatches {
  int batch = 0, channels = 0, height = 0, width = 0;
  int kernel = 0, stride = 1, padding = 0;
  int out_height = 0, out_width = 0;
  long sample_stride = 0, channel_stride = 0, row_stride = 0, column_stride = 0;
};

/// One target's kernels. SiLU(z) = z s with s = sigmoid(z) = 1 / (1 + exp(-z)).
struct KernelSet {
  void (*gemm)(const Gemm& problem);
  /// gemm with op(B) read through offsets (OffsetGemm), the same bits.
  void (*offset_gemm)(const OffsetGemm& problem);
  /// A convolution of kPixelConvFilters filters with its pixels in the lanes (PixelConv): the
  /// bits of offset_gemm on that product.
  void (*pixel_conv)(const PixelConv& problem);
  /// Its weight gradient (PixelConvGradient), with the pixels in the lanes on AVX-512.
  void (*pixel_conv_weights)(const PixelConvGradient& problem);
  /// even[i] = v[2 i] and odd[i] = v[2 i + 1] for the n values v of a row: a row of an image
  /// stored by column phase for a convolution of stride 2 (PixelConv). v = x, or with mean and
  /// inv_scale (n each; both or neither) v[i] = (x[i] - mean[i]) inv_scale[i], rounded after the
  /// subtraction and after the product: Normalizer::normalize's bits, the training batch
  /// normalized as it is read.
  void (*deinterleave)(std::ptrdiff_t n, const float* x, const float* mean, const float* inv_scale,
                       float* even, float* odd);
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
  /// col2im: adds each entry of the K x N patch matrix (ConvPatches) `patches` (ld K) to the pixel
  /// it was read from (entries of the padding are dropped). `image` is accumulated into, not
  /// cleared. The adjoint of reading the patches (an input gradient).
  void (*col2im)(const ConvPatches& shape, const float* patches, float* image);
  /// row2im: the same for the patch matrix transposed, N x K with leading dimension `ld` >= N
  /// (entry (pixel j, patch entry p) at rows[j + p ld]), as the first layer's input gradient
  /// delta^T W comes out of its product.
  void (*row2im)(const ConvPatches& shape, const float* rows, long ld, float* image);
  /// Box-Muller's pairs (box_muller.hpp) with glibc's logf, cosf and sinf transcribed in double
  /// lanes (box_muller-inl.h) on AVX2 and AVX-512; libm itself (box_muller_pairs_libm) on the
  /// targets without FMA, whose rounding could not follow glibc's FMA variants.
  void (*box_muller)(std::ptrdiff_t pairs, const std::uint64_t* bits, float* out,
                     const LibmFloatConstants& constants);
  /// The parts of the same pairs, for the checks against libm (box_muller_parts_libm).
  void (*box_muller_parts)(std::ptrdiff_t pairs, const std::uint64_t* bits, float* radius,
                           float* cosine, float* sine, const LibmFloatConstants& constants);
  /// The Highway target (HWY_AVX3, HWY_AVX2, ...) the functions are compiled for.
  std::int64_t target;
};

/// The Highway targets this build compiled and this CPU runs, best first
/// (hwy::SupportedAndGeneratedTargets(); hwy::TargetName names them).
std::vector<std::int64_t> available_targets();
/// Highway's name of a target ("AVX3", "AVX2", "SSE4", "EMU128", "SCALAR", ...).
std::string target_name(std::int64_t target);
/// The kernels compiled for `target`, one of available_targets().
const KernelSet& kernels_of_target(std::int64_t target);
/// The set Highway's dynamic dispatch picks: the best of available_targets().
const KernelSet& best_kernels();

/// The set for `isa` (which must be supported), and the one in use (kernel_isa()).
const KernelSet& kernels_for(KernelIsa isa);
const KernelSet& active();

}  // namespace handcentric::policy::kernels
