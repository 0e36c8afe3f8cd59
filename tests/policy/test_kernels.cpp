// The float32 kernels of every Highway target this build compiled and this CPU runs (AVX-512,
// AVX2, SSE4, the portable code; policy/src/kernels) against a double-precision reference: GEMM in
// the three orientations Mlp uses and the fourth, with biases, every edge of the blocking
// (partial tiles, k beyond one k block, n beyond one column block, strides, k = 0), the narrow
// products of sampling (n <= 16) with unaligned columns, the SiLU kernels, the squared norm
// and Adam; the image encoder's first-layer product with the pixels in the lanes against the
// offset product's bits, and the split of a row into its even and odd floats. Then the whole
// Mlp per named kernel set (kernels.hpp) against MlpT<double>. The checks are seen failing on
// planted faults. Under ASan, the masked accesses ASan cannot see are checked lane by lane
// (kernels/asan_lanes.hpp).
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/policy/adam.hpp"
#include "handcentric/policy/kernels.hpp"
#include "handcentric/policy/mlp.hpp"
#include "handcentric/policy/normalizer.hpp"
#include "kernels/asan_lanes.hpp"
#include "kernels/kernel_set.hpp"
#include "throws.hpp"
#include "worst_error.hpp"  // tests/support

using namespace handcentric;
using namespace handcentric::policy;
using kernels::Op;

namespace {

// Every target's kernels, with its name (AVX3, AVX2, SSE4, SCALAR or EMU128, ...).
std::vector<std::pair<std::string, const kernels::KernelSet*>> every_target() {
  std::vector<std::pair<std::string, const kernels::KernelSet*>> sets;
  for (std::int64_t target : kernels::available_targets()) {
    sets.emplace_back(kernels::target_name(target), &kernels::kernels_of_target(target));
  }
  return sets;
}

std::vector<KernelIsa> supported_sets() {
  std::vector<KernelIsa> sets;
  for (KernelIsa isa : {KernelIsa::generic, KernelIsa::avx2, KernelIsa::avx512}) {
    if (kernel_isa_supported(isa)) sets.push_back(isa);
  }
  return sets;
}

// Restores the process-wide kernel set when a test leaves.
struct KernelSetGuard {
  KernelIsa saved = kernel_isa();
  ~KernelSetGuard() { set_kernel_isa(saved); }
};

std::vector<float> random_floats(std::size_t n, std::mt19937_64& rng) {
  std::vector<float> v(n);
  for (float& x : v) x = static_cast<float>(2.0 * uniform01(rng) - 1.0);
  return v;
}

// A GEMM problem with its own storage: op(A) m x k, op(B) k x n, leading dimensions padded
// by `pad` so strides differ from the sizes; C is prefilled with garbage (it must be overwritten).
struct GemmProblem {
  Op op_a, op_b;
  int m, n, k, pad;
  bool bias;
  std::vector<float> a, b, row_bias, c;
  int lda, ldb, ldc;

  GemmProblem(Op op_a_, Op op_b_, int m_, int n_, int k_, int pad_, bool bias_,
              std::mt19937_64& rng)
      : op_a(op_a_), op_b(op_b_), m(m_), n(n_), k(k_), pad(pad_), bias(bias_) {
    const int a_rows = op_a == Op::none ? m : k, a_cols = op_a == Op::none ? k : m;
    const int b_rows = op_b == Op::none ? k : n, b_cols = op_b == Op::none ? n : k;
    lda = a_rows + pad;
    ldb = b_rows + pad;
    ldc = m + pad;
    a = random_floats(static_cast<std::size_t>(lda) * std::max(a_cols, 1), rng);
    b = random_floats(static_cast<std::size_t>(ldb) * std::max(b_cols, 1), rng);
    row_bias = random_floats(static_cast<std::size_t>(m), rng);
    c.assign(static_cast<std::size_t>(ldc) * std::max(n, 1), 1e30f);
  }
  float A(int i, int p) const { return op_a == Op::none ? a[i + p * lda] : a[p + i * lda]; }
  float B(int p, int j) const { return op_b == Op::none ? b[p + j * ldb] : b[j + p * ldb]; }
  kernels::Gemm gemm() {
    return {op_a,     op_b, m, n, k, a.data(), lda, b.data(), ldb, bias ? row_bias.data() : nullptr,
            c.data(), ldc};
  }
};

// The worst |C - C_ref| / bound over C, with C_ref in double and the bound the float rounding
// of a k-term sum, 4 k eps (sum_p |a_ip b_pj| + |bias_i|) + 1e-30. `skip_last_term` plants a
// fault in the reference (the last product left out), which the check must catch.
double gemm_error(const GemmProblem& problem, bool skip_last_term = false) {
  double worst = 0.0;
  for (int j = 0; j < problem.n; ++j) {
    for (int i = 0; i < problem.m; ++i) {
      double sum = problem.bias ? problem.row_bias[i] : 0.0;
      double magnitude = std::abs(sum);
      const int terms = skip_last_term ? problem.k - 1 : problem.k;
      for (int p = 0; p < terms; ++p) {
        const double term = static_cast<double>(problem.A(i, p)) * problem.B(p, j);
        sum += term;
        magnitude += std::abs(term);
      }
      const double bound = 4.0 * std::max(problem.k, 1) * 6e-8 * magnitude + 1e-30;
      worst = test::worst_of(worst, std::abs(problem.c[i + j * problem.ldc] - sum) / bound);
    }
  }
  return worst;
}

struct Shape {
  int m, n, k;
};

// Edges of the blocking of both vector sets (MR 32 / 16, NR 12 / 6, KC 256, NC 384; the short
// tile's MR 16 / 8) and the network's own shapes (57 -> 256 -> 256 -> 24 at batch 256 and 1).
const std::vector<Shape> kShapes = {
    {1, 1, 1},
    {3, 2, 5},
    {16, 6, 7},
    {17, 7, 9},
    {32, 12, 16},
    {33, 13, 31},
    {31, 11, 257},
    {24, 256, 256},
    {256, 256, 57},
    {256, 57, 256},
    {57, 256, 256},
    {40, 400, 20},
    {256, 1, 256},
    {24, 1, 256},
    {300, 1, 57},
    {7, 1, 3},
    {400, 1, 5},
    {5, 3, 0},
    // the narrow kernel (n <= 16: groups of up to 8 columns, 24 / N vectors of rows)
    {50, 3, 20},
    {100, 4, 33},
    {70, 5, 9},
    {260, 8, 40},
    {33, 9, 17},
    {400, 16, 5},
    {17, 15, 64},
    // the one-vector tile of short products (m <= the lanes of a vector: 16 on AVX-512, 8 on
    // AVX2, 4 on SSE4, 1 for the scalar code), beyond one k block and one column block
    {16, 40, 300},
    {9, 37, 20},
    {8, 400, 31},
    {4, 30, 5},
    {1, 25, 9},
    // the half-width tile (m <= 8 on AVX-512): a first layer of 8 filters, forward (K = 54,
    // 6 channels of 3 x 3) and its weight gradient (k = the batch's pixels)
    {8, 300, 54},
    {8, 54, 600},
    {6, 20, 13}};

}  // namespace

TEST_CASE("every_kernel_set_multiplies_like_the_double_reference", "[unit]") {
  std::mt19937_64 rng(11);
  for (const auto& [name, set] : every_target()) {
    INFO("target " << name);
    for (const Shape& shape : kShapes) {
      for (Op op_a : {Op::none, Op::transpose}) {
        for (Op op_b : {Op::none, Op::transpose}) {
          for (int pad : {0, 3}) {
            const bool bias = (shape.m + shape.k + pad) % 2 == 0;
            GemmProblem problem(op_a, op_b, shape.m, shape.n, shape.k, pad, bias, rng);
            set->gemm(problem.gemm());
            INFO("m " << shape.m << " n " << shape.n << " k " << shape.k << " op_a " << int(op_a)
                      << " op_b " << int(op_b) << " pad " << pad << " bias " << bias);
            CHECK(gemm_error(problem) <= 1.0);
          }
        }
      }
    }
  }
}

TEST_CASE("the_gemm_check_catches_a_product_that_misses_a_term", "[unit]") {
  // Planted fault: compare the kernel against a reference that leaves out the last k term
  // (what an off-by-one in the k loop of a kernel would do).
  std::mt19937_64 rng(12);
  for (const auto& [name, set] : every_target()) {
    INFO("target " << name);
    // The blocked, narrow and short-tile products (m = 1, 4, 8, 16: each target's one vector).
    for (const Shape& shape : {Shape{33, 13, 31}, Shape{256, 1, 256}, Shape{16, 40, 31},
                               Shape{8, 40, 31}, Shape{4, 40, 31}, Shape{1, 40, 31}}) {
      GemmProblem problem(Op::none, Op::none, shape.m, shape.n, shape.k, 0, false, rng);
      set->gemm(problem.gemm());
      CHECK(gemm_error(problem) <= 1.0);
      CHECK(gemm_error(problem, /*skip_last_term=*/true) > 1.0);
    }
  }
}

// Gemm::a_row_sums (db = delta 1 beside dW = delta x^T): the worst |sum_i - ref_i| / bound over
// op(A)'s rows, ref in double; `skip_last_term` plants a fault in the reference (the last k term
// left out), which the check must catch.
double row_sums_error(const GemmProblem& problem, const std::vector<float>& sums,
                      bool skip_last_term = false) {
  double worst = 0.0;
  for (int i = 0; i < problem.m; ++i) {
    double sum = 0.0, magnitude = 0.0;
    for (int p = 0; p < (skip_last_term ? problem.k - 1 : problem.k); ++p) {
      sum += problem.A(i, p);
      magnitude += std::abs(problem.A(i, p));
    }
    const double bound = 4.0 * std::max(problem.k, 1) * 6e-8 * magnitude + 1e-30;
    worst = test::worst_of(worst, std::abs(sums[i] - sum) / bound);
  }
  return worst;
}

TEST_CASE("row_sums_of_a_are_the_narrow_products_bits_on_every_path", "[unit]") {
  // The blocked nest adds A's rows up while it packs A; every other path in a pass of its own.
  // On every target and shape the sums match the double reference, C is still the product, and
  // with op(A) = A (the bias gradients') the sums have the bits of the narrow product A 1, which
  // computed the bias gradients before, so trained weights keep their bits.
  std::mt19937_64 rng(17);
  for (const auto& [name, set] : every_target()) {
    INFO("target " << name);
    for (const Shape& shape : kShapes) {
      for (Op op_a : {Op::none, Op::transpose}) {
        for (Op op_b : {Op::none, Op::transpose}) {
          GemmProblem problem(op_a, op_b, shape.m, shape.n, shape.k, 3, false, rng);
          std::vector<float> sums(static_cast<std::size_t>(shape.m), 1e30f);
          kernels::Gemm gemm = problem.gemm();
          gemm.a_row_sums = sums.data();
          set->gemm(gemm);
          INFO("m " << shape.m << " n " << shape.n << " k " << shape.k << " op_a " << int(op_a)
                    << " op_b " << int(op_b));
          CHECK(gemm_error(problem) <= 1.0);
          CHECK(row_sums_error(problem, sums) <= 1.0);
          if (op_a == Op::none) {  // against the narrow product by ones, a call of its own
            const std::vector<float> ones(static_cast<std::size_t>(std::max(shape.k, 1)), 1.0f);
            std::vector<float> narrow(static_cast<std::size_t>(shape.m), -1e30f);
            set->gemm({Op::none, Op::none, shape.m, 1, shape.k, problem.a.data(), problem.lda,
                       ones.data(), std::max(shape.k, 1), nullptr, narrow.data(), shape.m});
            CHECK(sums == narrow);
          }
          if (shape.k >= 2) {  // planted fault: a reference that leaves out the last term
            CHECK(row_sums_error(problem, sums, /*skip_last_term=*/true) > 1.0);
          }
        }
      }
    }
  }
}

TEST_CASE("a_product_split_over_k_into_accumulating_calls_is_one_product_bit_for_bit", "[unit]") {
  // ConvEncoder sums a weight gradient chunk by chunk (Gemm::accumulate, each chunk a multiple
  // of the k block): C and the row sums must be the bits of one call over the whole k, and
  // C_before + the product to within the double reference's bound. Shapes of the encoder's
  // weight gradients (B = patches^T or patches), and edge tiles; n > 16 (a single narrow call,
  // n <= 16, sums all of k in one pass: splitting it rounds differently).
  std::mt19937_64 rng(18);
  constexpr int kBlock = kernels::kProductKBlock;
  for (const auto& [name, set_pointer] : every_target()) {
    INFO("target " << name);
    // A plain pointer for the lambda below: clang 14 cannot capture a structured binding.
    const kernels::KernelSet* set = set_pointer;
    for (const Shape& shape :
         {Shape{32, 144, 3 * kBlock + 40}, Shape{16, 36, 2 * kBlock}, Shape{33, 17, kBlock + 1},
          Shape{7, 25, 2 * kBlock + 9}, Shape{8, 54, 3 * kBlock}}) {
      for (Op op_b : {Op::none, Op::transpose}) {
        GemmProblem problem(Op::none, op_b, shape.m, shape.n, shape.k, 3, false, rng);
        std::vector<float> sums(static_cast<std::size_t>(shape.m), 1e30f);
        kernels::Gemm whole = problem.gemm();
        whole.a_row_sums = sums.data();
        set->gemm(whole);
        const std::vector<float> c_whole = problem.c, sums_whole = sums;
        // The same product in calls of one k block each, the last one shorter; `plant`: the last
        // call writes C instead of adding to it (a planted fault the reference check must catch).
        const auto split = [&](bool plant) {
          std::fill(problem.c.begin(), problem.c.end(), 1e30f);
          std::fill(sums.begin(), sums.end(), 1e30f);
          for (int p0 = 0; p0 < shape.k; p0 += kBlock) {
            kernels::Gemm part = problem.gemm();
            part.k = std::min(kBlock, shape.k - p0);
            part.a = problem.a.data() + static_cast<long>(p0) * problem.lda;
            part.b =
                problem.b.data() + (op_b == Op::none ? p0 : static_cast<long>(p0) * problem.ldb);
            part.a_row_sums = sums.data();
            part.accumulate = p0 > 0 && !(plant && p0 + kBlock >= shape.k);
            set->gemm(part);
          }
        };
        split(false);
        INFO("m " << shape.m << " n " << shape.n << " k " << shape.k << " op_b " << int(op_b));
        CHECK(problem.c == c_whole);
        CHECK(sums == sums_whole);
        CHECK(gemm_error(problem) <= 1.0);
        CHECK(row_sums_error(problem, sums) <= 1.0);
        split(true);
        CHECK(gemm_error(problem) > 1.0);
      }
    }
  }
}

// offset_gemm reads op(B)(p, j) = b[row_offsets[p] + column_offsets[j]] in place; its answer
// must be gemm's on that op(B) stored as a matrix, bit for bit: C, the sigmoid kept by the SiLU
// epilogue, the row sums, and C added to. Offsets are random, overlapping and unordered, as a
// convolution's windows overlap; every shape of the blocking, n <= 16 included (gathered there).
TEST_CASE("offset_products_have_the_bits_of_the_product_on_their_matrix", "[unit]") {
  std::mt19937_64 rng(19);
  for (const auto& [name, set_pointer] : every_target()) {
    INFO("target " << name);
    // A plain pointer for the lambda below: clang 14 cannot capture a structured binding.
    const kernels::KernelSet* set = set_pointer;
    for (const Shape& shape : kShapes) {
      if (static_cast<long>(shape.m) * shape.n * shape.k > (1L << 21)) continue;  // ASan's time
      for (Op op_a : {Op::none, Op::transpose}) {
        for (int variant = 0; variant < 3; ++variant) {  // bias and SiLU; row sums; accumulate
          const bool bias = variant == 0, row_sums = variant == 1, accumulate = variant == 2;
          GemmProblem problem(op_a, Op::none, shape.m, shape.n, shape.k, 2, bias, rng);
          const long span = 3L * (shape.k + shape.n) + 1;
          const std::vector<float> source = random_floats(static_cast<std::size_t>(2 * span), rng);
          std::vector<long> rows(static_cast<std::size_t>(std::max(shape.k, 1))),
              columns(static_cast<std::size_t>(std::max(shape.n, 1)));
          for (long& offset : rows) offset = static_cast<long>(uniform01(rng) * span);
          for (long& offset : columns) offset = static_cast<long>(uniform01(rng) * span);
          for (int j = 0; j < shape.n; ++j) {
            for (int p = 0; p < shape.k; ++p) {
              problem.b[p + static_cast<std::size_t>(j) * problem.ldb] =
                  source[rows[p] + columns[j]];
            }
          }
          const std::vector<float> c_before = random_floats(problem.c.size(), rng);
          // One run: C, the sigmoid (or the row sums) and what they started from.
          const auto run = [&](const kernels::OffsetGemm* offsets) {
            problem.c = c_before;
            std::vector<float> kept(problem.c.size(), 7.0f);
            kernels::Gemm product = problem.gemm();
            product.accumulate = accumulate;
            if (bias) {
              product.epilogue = kernels::Epilogue::silu;
              product.sigmoid = kept.data();
              product.lds = problem.ldc;
            }
            if (row_sums) product.a_row_sums = kept.data();
            if (offsets == nullptr) {
              set->gemm(product);
            } else {
              kernels::OffsetGemm read = *offsets;
              read.product = product;
              read.product.b = source.data();
              set->offset_gemm(read);
            }
            return std::pair{problem.c, kept};
          };
          INFO("m " << shape.m << " n " << shape.n << " k " << shape.k << " op_a " << int(op_a)
                    << " variant " << variant);
          const auto expected = run(nullptr);
          kernels::OffsetGemm offsets{{}, rows.data(), columns.data()};
          CHECK(run(&offsets) == expected);
          // Planted fault: the last row of op(B) read from the first one's place.
          if (shape.k >= 2 && shape.m * shape.n >= 1) {
            std::vector<long> wrong = rows;
            wrong.back() = wrong.front() == wrong.back() ? wrong.back() + 1 : wrong.front();
            kernels::OffsetGemm planted{{}, wrong.data(), columns.data()};
            CHECK(run(&planted).first != expected.first);
          }
        }
      }
    }
  }
}

// The input of a PixelConv or PixelConvGradient: k patch entries at random offsets (windows that
// overlap) and `rows` rows of `width` consecutive pixels each, from random starts.
struct RowWindows {
  std::vector<float> input;
  std::vector<long> patches, pixels;
  RowWindows(int k, int rows, int width, std::mt19937_64& rng)
      : patches(static_cast<std::size_t>(k)), pixels(static_cast<std::size_t>(rows) * width) {
    const long span = 2L * k + 3L * width + 1;
    input = random_floats(static_cast<std::size_t>(4 * span), rng);
    for (long& offset : patches) offset = static_cast<long>(uniform01(rng) * span);
    for (int r = 0; r < rows; ++r) {
      const long start = static_cast<long>(uniform01(rng) * 2 * span);
      for (int x = 0; x < width; ++x) pixels[static_cast<std::size_t>(r) * width + x] = start + x;
    }
  }
};

// pixel_conv (the image encoder's first layer of 8 filters, with the pixels in the lanes on
// AVX-512, the offset product itself on the other targets) must give offset_gemm's bits on the
// same product with the SiLU epilogue, wherever offset_gemm runs
// the blocked nest (more than 16 pixels): C and the sigmoid, rows of every width against the
// vectors (a partial tile, one pixel), k within one k block and beyond it (the blocked nest's
// order of the sums), overlapping windows at random offsets.
TEST_CASE("pixel_products_have_the_bits_of_the_offset_product", "[unit]") {
  constexpr int kFilters = kernels::kPixelConvFilters;
  std::mt19937_64 rng(23);
  for (const auto& [name, set_pointer] : every_target()) {
    INFO("target " << name);
    const kernels::KernelSet* set = set_pointer;
    for (int k : {1, 9, 54, 300}) {
      // rows x width: n > 16, the products offset_gemm runs on the blocked nest.
      for (const auto& shape : std::vector<std::pair<int, int>>{
               {20, 1}, {4, 5}, {3, 16}, {3, 17}, {2, 32}, {3, 33}, {2, 47}}) {
        const int rows = shape.first, width = shape.second, n = rows * width;
        const std::vector<float> weights =
            random_floats(static_cast<std::size_t>(kFilters) * k, rng);
        const std::vector<float> bias = random_floats(kFilters, rng);
        const RowWindows windows(k, rows, width, rng);
        const std::vector<float>& input = windows.input;
        const std::vector<long>&patches = windows.patches, &pixels = windows.pixels;
        const std::size_t size = static_cast<std::size_t>(kFilters) * n;
        std::vector<float> c(size, 7.0f), sigmoid(size, 7.0f);
        const auto expected_run = [&] {
          kernels::Gemm product{Op::none, Op::none,       kFilters, n,
                                k,        weights.data(), kFilters, input.data(),
                                k,        bias.data(),    c.data(), kFilters};
          product.epilogue = kernels::Epilogue::silu;
          product.sigmoid = sigmoid.data();
          product.lds = kFilters;
          set->offset_gemm({product, patches.data(), pixels.data()});
          return std::pair{c, sigmoid};
        };
        const auto pixel_run = [&](const long* patch_offsets, int terms) {
          std::fill(c.begin(), c.end(), 7.0f);
          std::fill(sigmoid.begin(), sigmoid.end(), 7.0f);
          set->pixel_conv({terms, rows, width, weights.data(), bias.data(), input.data(),
                           patch_offsets, pixels.data(), c.data(), sigmoid.data()});
          return std::pair{c, sigmoid};
        };
        INFO("k " << k << " width " << width);
        const auto expected = expected_run();
        CHECK(pixel_run(patches.data(), k) == expected);
        // Planted faults: the last patch entry read from the first one's place; a term short.
        if (k >= 2) {
          std::vector<long> wrong = patches;
          wrong.back() = wrong.front() == wrong.back() ? wrong.back() + 1 : wrong.front();
          CHECK(pixel_run(wrong.data(), k).first != expected.first);
          CHECK(pixel_run(patches.data(), k - 1).first != expected.first);
        }
      }
    }
  }
}

// pixel_conv_weights (the first layer's weight gradient, dW = delta P^T and db = delta 1): the
// sums of a double reference on every target, for rows of every width against the vectors
// (partial vectors, one pixel), more rows than one chunk, k with and without a tail of entries
// beside the 6-entry tiles, and overlapping windows at random offsets; the offset product's
// bits on the targets where it is that product. dW and db are written, not accumulated.
TEST_CASE("pixel_weight_gradients_are_the_sums_of_the_double_reference", "[unit]") {
  constexpr int kFilters = kernels::kPixelConvFilters;
  std::mt19937_64 rng(31);
  for (const auto& [name, set_pointer] : every_target()) {
    INFO("target " << name);
    const kernels::KernelSet* set = set_pointer;
    const bool offset_product = name.rfind("AVX3", 0) != 0;  // the pixels in the lanes on AVX-512
    for (int k : {1, 7, 54}) {
      for (const auto& shape : std::vector<std::pair<int, int>>{
               {20, 1}, {4, 5}, {3, 16}, {3, 17}, {30, 32}, {3, 33}, {2, 47}}) {
        const int rows = shape.first, width = shape.second, n = rows * width;
        const std::vector<float> delta = random_floats(static_cast<std::size_t>(kFilters) * n, rng);
        const RowWindows windows(k, rows, width, rng);
        const std::vector<float>& input = windows.input;
        const std::vector<long>&patches = windows.patches, &pixels = windows.pixels;
        // The reference, and the scale of each sum (the sum of its terms' magnitudes).
        std::vector<double> weights(static_cast<std::size_t>(kFilters) * k), bias(kFilters);
        std::vector<double> weight_scale(weights.size()), bias_scale(kFilters);
        for (int j = 0; j < n; ++j) {
          for (int f = 0; f < kFilters; ++f) {
            const double d = delta[static_cast<std::size_t>(j) * kFilters + f];
            bias[f] += d;
            bias_scale[f] += std::abs(d);
            for (int p = 0; p < k; ++p) {
              const double term = d * input[patches[p] + pixels[j]];
              weights[static_cast<std::size_t>(p) * kFilters + f] += term;
              weight_scale[static_cast<std::size_t>(p) * kFilters + f] += std::abs(term);
            }
          }
        }
        std::vector<float> d_weights(weights.size()), d_bias(kFilters);
        const auto run = [&](const long* patch_offsets, int terms, int row_count) {
          std::fill(d_weights.begin(), d_weights.end(), 7.0f);
          std::fill(d_bias.begin(), d_bias.end(), 7.0f);
          set->pixel_conv_weights({terms, row_count, width, input.data(), patch_offsets,
                                   pixels.data(), delta.data(), d_weights.data(), d_bias.data()});
          // The worst error against the reference, in units of float rounding of the terms.
          double worst = 0;
          for (std::size_t i = 0; i < weights.size(); ++i) {
            worst = test::worst_of(worst, std::abs(d_weights[i] - weights[i]) / weight_scale[i]);
          }
          for (int f = 0; f < kFilters; ++f) {
            worst = test::worst_of(worst, std::abs(d_bias[f] - bias[f]) / bias_scale[f]);
          }
          return worst;
        };
        INFO("k " << k << " rows " << rows << " width " << width);
        // n terms of float rounding at most (each term and each addition), 1e-7 apiece.
        CHECK(run(patches.data(), k, rows) < 1e-7 * (n + 2));
        if (offset_product) {
          std::vector<float> expected_weights(weights.size(), 7.0f), expected_bias(kFilters, 7.0f);
          kernels::Gemm product{Op::none,
                                Op::none,
                                kFilters,
                                k,
                                n,
                                delta.data(),
                                kFilters,
                                input.data(),
                                n,
                                nullptr,
                                expected_weights.data(),
                                kFilters};
          product.a_row_sums = expected_bias.data();
          set->offset_gemm({product, pixels.data(), patches.data()});
          run(patches.data(), k, rows);
          CHECK(d_weights == expected_weights);
          CHECK(d_bias == expected_bias);
        }
        // Planted faults: the last patch entry read from the first one's place; a row left out.
        if (k >= 2) {
          std::vector<long> wrong = patches;
          wrong.back() = wrong.front() == wrong.back() ? wrong.back() + 1 : wrong.front();
          CHECK(run(wrong.data(), k, rows) > 1e-3);
        }
        if (rows >= 2) CHECK(run(patches.data(), k, rows - 1) > 1e-3);
      }
    }
  }
}

// deinterleave splits a row into its even and odd floats (the first layer's padded rows by
// column phase), every length around the vectors' widths; with a mean and an inv_scale, each
// value normalized first with Normalizer::normalize's bits (the test compares with that
// function's output on the same row). Planted fault: an inv_scale a rounding step off.
TEST_CASE("deinterleave_splits_a_row_into_its_even_and_odd_floats", "[unit]") {
  std::mt19937_64 rng(29);
  for (const auto& [name, set] : every_target()) {
    for (int n = 0; n <= 70; ++n) {
      INFO("target " << name << " n " << n);
      const std::vector<float> x = random_floats(static_cast<std::size_t>(n), rng);
      Eigen::VectorXd mean(n), scale(n);
      for (int i = 0; i < n; ++i) {
        mean[i] = 3.0 * uniform01(rng) - 1.5;
        scale[i] = 0.01 + 3.0 * uniform01(rng);
      }
      const Normalizer normalizer(mean, scale);
      Eigen::MatrixXf expected = Eigen::Map<const Eigen::MatrixXf>(x.data(), n, 1);
      normalizer.normalize(expected);
      Eigen::VectorXf wrong_inv_scale = normalizer.inv_scale_float();
      for (float& s : wrong_inv_scale) s = std::nextafter(s, 100.0f);
      const kernels::KernelSet* target = set;  // clang 14 captures no structured binding
      const auto split = [&](const float* m, const float* s, const float* values) {
        // One float of guard past each half: nothing may be written there.
        std::vector<float> even((n + 1) / 2 + 1, 5.0f), odd(n / 2 + 1, 5.0f);
        target->deinterleave(n, x.data(), m, s, even.data(), odd.data());
        bool right = even.back() == 5.0f && odd.back() == 5.0f;
        for (int i = 0; i < n; ++i) right = right && (i % 2 == 0 ? even : odd)[i / 2] == values[i];
        return right;
      };
      CHECK(split(nullptr, nullptr, x.data()));
      CHECK(split(normalizer.mean_float().data(), normalizer.inv_scale_float().data(),
                  expected.data()));
      // Planted fault: each 1 / scale one float up (a product can round to the same float, but
      // not all of eight).
      if (n >= 8)
        CHECK_FALSE(split(normalizer.mean_float().data(), wrong_inv_scale.data(), expected.data()));
    }
  }
}

TEST_CASE("a_products_rows_have_the_same_bits_whichever_tile_computes_them", "[unit]") {
  // vector_gemm picks the tile by op(A)'s rows (the half-width one up to 8 on AVX-512, the
  // one-vector one up to a vector, the two-vector one beyond); each row of C is the same sum in
  // the same order on all of them, so trained weights do not depend on the choice. A product of
  // m rows against the same product with one row more (the next tile up): the first m rows of C
  // must be equal bit for bit. Planted fault: one entry of A changed in the larger product.
  std::mt19937_64 rng(19);
  for (const auto& [name, set] : every_target()) {
    INFO("target " << name);
    for (const int m : {4, 8, 16, 32}) {
      for (Op op_b : {Op::none, Op::transpose}) {
        const int n = 40, k = 300;
        GemmProblem large(Op::none, op_b, m + 1, n, k, 0, true, rng);
        set->gemm(large.gemm());
        // The first m rows of A, the same B and bias.
        GemmProblem small(Op::none, op_b, m, n, k, 0, true, rng);
        for (int p = 0; p < k; ++p) {
          for (int i = 0; i < m; ++i) small.a[i + p * small.lda] = large.a[i + p * large.lda];
        }
        small.b = large.b;
        std::copy(large.row_bias.begin(), large.row_bias.begin() + m, small.row_bias.begin());
        set->gemm(small.gemm());
        INFO("m " << m << " op_b " << int(op_b));
        const auto first_rows_equal = [&] {
          for (int j = 0; j < n; ++j) {
            for (int i = 0; i < m; ++i) {
              if (small.c[i + j * small.ldc] != large.c[i + j * large.ldc]) return false;
            }
          }
          return true;
        };
        CHECK(first_rows_equal());
        large.a[m / 2 + 7 * large.lda] += 0.5f;  // planted fault
        set->gemm(large.gemm());
        CHECK_FALSE(first_rows_equal());
      }
    }
  }
}

// The double reference Z = op(A) op(B) + b 1^T of a problem, and the sum of its terms'
// magnitudes, entry (i, j) at i + j m: computed once, for the check and its planted fault.
struct ReferenceProduct {
  std::vector<double> z, magnitude;
};

ReferenceProduct reference_product(const GemmProblem& problem) {
  ReferenceProduct reference;
  const std::size_t size = static_cast<std::size_t>(problem.m) * problem.n;
  reference.z.resize(size);
  reference.magnitude.resize(size);
  for (int j = 0; j < problem.n; ++j) {
    for (int i = 0; i < problem.m; ++i) {
      double z = problem.bias ? problem.row_bias[i] : 0.0, magnitude = std::abs(z);
      for (int p = 0; p < problem.k; ++p) {
        z += static_cast<double>(problem.A(i, p)) * problem.B(p, j);
        magnitude += std::abs(static_cast<double>(problem.A(i, p)) * problem.B(p, j));
      }
      reference.z[i + static_cast<std::size_t>(j) * problem.m] = z;
      reference.magnitude[i + static_cast<std::size_t>(j) * problem.m] = magnitude;
    }
  }
  return reference;
}

// The epilogues on every path of the product (blocked, narrow, k = 0): C against the double
// reference Z followed by SiLU, or by the product with SiLU'(z) = s + a (1 - s) from given s and
// a (leading dimension lds, unlike C's). Returns the worst error over C in units of the bound;
// `skip_epilogue` plants a fault in the reference (the epilogue left out), which the check must
// catch.
double epilogue_error(const GemmProblem& problem, const ReferenceProduct& reference,
                      kernels::Epilogue epilogue, int lds, const std::vector<float>& s_in,
                      const std::vector<float>& a_in, const std::vector<float>& s_out,
                      bool skip_epilogue = false) {
  double worst = 0.0;
  for (int j = 0; j < problem.n; ++j) {
    for (int i = 0; i < problem.m; ++i) {
      const double z = reference.z[i + static_cast<std::size_t>(j) * problem.m];
      const double magnitude = reference.magnitude[i + static_cast<std::size_t>(j) * problem.m];
      const long at = i + static_cast<long>(j) * problem.ldc, at_s = i + static_cast<long>(j) * lds;
      double expected = z, bound = 4.0 * std::max(problem.k, 1) * 6e-8 * magnitude + 1e-30;
      if (!skip_epilogue && epilogue == kernels::Epilogue::silu) {
        const double sigmoid = 1.0 / (1.0 + std::exp(-z));
        expected = z * sigmoid;
        bound = bound * 1.1 + 1e-6 * std::abs(expected) +
                1e-30;  // SiLU' <= 1.1, plus the sigmoid's error
        if (!s_out.empty())
          worst = test::worst_of(worst, std::abs(s_out[at_s] - sigmoid) / (bound + 1e-6 * sigmoid));
      } else if (!skip_epilogue && epilogue == kernels::Epilogue::silu_derivative) {
        const double derivative = s_in[at_s] + a_in[at_s] * (1.0 - s_in[at_s]);
        const double terms =
            std::abs(s_in[at_s]) + std::abs(a_in[at_s] * (1.0 - s_in[at_s]));  // float rounds these
        expected = z * derivative;
        bound = bound * std::abs(derivative) +
                4.0 * 6e-8 * (std::abs(z) * terms + std::abs(expected)) + 1e-30;
      }
      worst = test::worst_of(worst, std::abs(problem.c[at] - expected) / bound);
    }
  }
  return worst;
}

TEST_CASE("every_kernel_set_applies_the_silu_epilogues_on_every_path", "[unit]") {
  std::mt19937_64 rng(15);
  for (const auto& [name, set] : every_target()) {
    INFO("target " << name);
    for (const Shape& shape : kShapes) {
      for (Op op_a : {Op::none, Op::transpose}) {
        for (kernels::Epilogue epilogue :
             {kernels::Epilogue::silu, kernels::Epilogue::silu_derivative}) {
          // pad 0: C and the maps packed (ldc = lds = m), where a block's columns are one run
          // of values and the epilogue takes them in one call; pad 3: column by column.
          for (const auto& [keep_sigmoid, pad] :
               {std::pair{false, 3}, std::pair{true, 3}, std::pair{false, 0}, std::pair{true, 0}}) {
            if (epilogue == kernels::Epilogue::silu_derivative && !keep_sigmoid) continue;
            // Packed C on the shapes up to 2^21 multiply-adds: every path but the three largest
            // blocked shapes, whose double reference is most of this test's time under ASan.
            if (pad == 0 && static_cast<long>(shape.m) * shape.n * shape.k > (1L << 21)) continue;
            GemmProblem problem(op_a, Op::none, shape.m, shape.n, shape.k, pad, true, rng);
            for (float& x : problem.a) x *= 3.0f;  // z spans both tails of the sigmoid
            const int lds = pad == 0 ? problem.ldc : problem.ldc + 5;
            const std::size_t size = static_cast<std::size_t>(lds) * std::max(shape.n, 1);
            std::vector<float> s_in = random_floats(size, rng), a_in = random_floats(size, rng);
            for (float& x : s_in) x = 0.5f + 0.5f * x;  // a sigmoid is in (0, 1)
            std::vector<float> s_out(size, -1.0f);
            kernels::Gemm gemm = problem.gemm();
            gemm.epilogue = epilogue;
            gemm.lds = lds;
            if (epilogue == kernels::Epilogue::silu_derivative) {
              gemm.sigmoid = s_in.data();
              gemm.activation = a_in.data();
            } else if (keep_sigmoid) {
              gemm.sigmoid = s_out.data();
            }
            set->gemm(gemm);
            const std::vector<float>& kept =
                epilogue == kernels::Epilogue::silu && keep_sigmoid ? s_out : std::vector<float>{};
            INFO("m " << shape.m << " n " << shape.n << " k " << shape.k << " op_a " << int(op_a)
                      << " epilogue " << int(epilogue) << " keep_sigmoid " << keep_sigmoid
                      << " pad " << pad);
            const ReferenceProduct reference = reference_product(problem);
            CHECK(epilogue_error(problem, reference, epilogue, lds, s_in, a_in, kept) <= 1.0);
            if (shape.m * shape.n >= 4) {  // planted fault: a reference without the epilogue
              CHECK(epilogue_error(problem, reference, epilogue, lds, s_in, a_in, kept,
                                   /*skip_epilogue=*/true) > 1.0);
            }
          }
        }
      }
    }
  }
}

TEST_CASE("narrow_products_read_columns_at_every_offset_from_a_cache_line", "[unit]") {
  // Batch-1 sampling reads the weights where Eigen put them (16-byte aligned); the AVX-512
  // narrow kernel shifts its vectors to the cache line. Every start offset 0..15 floats,
  // lda % 16 == 0, for 1, 3 and 8 columns.
  std::mt19937_64 rng(13);
  const int m = 264, k = 40, lda = 272;
  std::vector<float> storage = random_floats(static_cast<std::size_t>(lda) * k + 16, rng);
  const std::vector<float> x = random_floats(8 * k, rng), bias = random_floats(m, rng);
  for (const auto& [name, set] : every_target()) {
    for (int n : {1, 3, 8}) {
      for (int offset = 0; offset < 16; ++offset) {
        const int ldc = m + 32;
        std::vector<float> y(static_cast<std::size_t>(ldc) * n, 7.0f);
        const float* a = storage.data() + offset;
        set->gemm(
            {Op::none, Op::none, m, n, k, a, lda, x.data(), k, bias.data(), y.data() + 16, ldc});
        double worst = 0.0;
        for (int j = 0; j < n; ++j) {
          for (int i = 0; i < m; ++i) {
            double sum = bias[i], magnitude = std::abs(sum);
            for (int p = 0; p < k; ++p) {
              sum += static_cast<double>(a[i + p * lda]) * x[p + j * k];
              magnitude += std::abs(static_cast<double>(a[i + p * lda]) * x[p + j * k]);
            }
            worst = test::worst_of(
                worst, std::abs(y[16 + i + j * ldc] - sum) / (4.0 * k * 6e-8 * magnitude));
          }
          // Nothing written outside C: the masked lanes stay untouched.
          for (int i = 0; i < 16; ++i) CHECK(y[i + j * ldc] == 7.0f);
          for (int i = 16 + m; i < ldc; ++i) CHECK(y[i + j * ldc] == 7.0f);
        }
        INFO(name << " n " << n << " offset " << offset);
        CHECK(worst <= 1.0);
      }
    }
  }
}

TEST_CASE("every_kernel_set_computes_silu_norm_and_adam_like_the_reference", "[unit]") {
  std::mt19937_64 rng(14);
  for (const auto& [name, set_pointer] : every_target()) {
    INFO("target " << name);
    const kernels::KernelSet& set = *set_pointer;
    for (int n : {1, 7, 8, 15, 16, 17, 100, 1000}) {
      std::vector<float> z = random_floats(n, rng);
      for (float& v : z) v *= 20.0f;  // both tails of the sigmoid
      if (n > 3) {
        z[0] = 95.0f;   // past the exp clamp: sigmoid 1, SiLU z
        z[1] = -95.0f;  // sigmoid ~0, SiLU ~0, never NaN
        z[2] = 0.0f;
      }
      std::vector<float> s(n), a(n), inplace = z, delta = random_floats(n, rng), delta0 = delta;
      set.silu_forward(n, z.data(), s.data(), a.data());
      set.silu(n, inplace.data());
      set.silu_backward(n, a.data(), s.data(), delta.data());
      for (int i = 0; i < n; ++i) {
        const double zd = z[i], sd = 1.0 / (1.0 + std::exp(-zd));
        const double derivative = sd * (1.0 + zd * (1.0 - sd));
        INFO("n " << n << " z " << zd);
        CHECK(std::abs(s[i] - sd) <= 1e-6 * sd + 1e-30);
        CHECK(std::abs(a[i] - zd * sd) <= 1e-6 * std::abs(zd * sd) + 1e-30);
        CHECK(std::abs(inplace[i] - zd * sd) <= 1e-6 * std::abs(zd * sd) + 1e-30);
        // SiLU' = s + a (1 - s) cancels near z = -1.28, so the bound has an absolute part: the
        // 1e-6 relative errors of s and a (checked above) in terms of size s and |a (1 - s)|.
        const double terms = sd + std::abs(zd * sd * (1.0 - sd));
        CHECK(std::abs(delta[i] - delta0[i] * derivative) <=
              1e-5 * std::abs(delta0[i] * derivative) + 1e-6 * std::abs(delta0[i]) * terms + 1e-30);
      }
      double norm = 0.0;
      for (float v : delta0) norm += static_cast<double>(v) * v;
      CHECK(std::abs(set.squared_norm(n, delta0.data()) - norm) <= 1e-12 * norm);

      std::vector<float> p = random_floats(n, rng), g = random_floats(n, rng),
                         m = random_floats(n, rng), v = random_floats(n, rng);
      for (float& x : v) x = std::abs(x);
      const std::vector<float> p0 = p, m0 = m, v0 = v;
      kernels::AdamUpdate update;
      update.n = n;
      update.parameters = p.data();
      update.gradient = g.data();
      update.gradient_scale = 0.5f;  // clipping
      update.m = m.data();
      update.v = v.data();
      update.beta1 = 0.9f;
      update.beta2 = 0.999f;
      update.step_size = 1e-3f;
      update.inv_sqrt_bias2 = 1.2f;
      update.epsilon = 1e-8f;
      update.decay = 0.99f;
      set.adam(update);
      for (int i = 0; i < n; ++i) {
        const double gi = 0.5 * g[i];
        const double m1 = 0.9 * m0[i] + 0.1 * gi, v1 = 0.999 * v0[i] + 0.001 * gi * gi;
        const double p1 = 0.99 * p0[i] - 1e-3 * m1 / (std::sqrt(v1) * 1.2 + 1e-8);
        CHECK(std::abs(m[i] - m1) <= 1e-6);
        CHECK(std::abs(v[i] - v1) <= 1e-6);
        CHECK(std::abs(p[i] - p1) <= 1e-6);
      }
    }
  }
}

TEST_CASE("mlp_on_every_kernel_set_matches_the_double_network", "[unit]") {
  // Forward, backward (parameter and input gradients) and batch-1 inference of one network
  // with the same parameters in float on each kernel set and in double (Eigen).
  KernelSetGuard guard;
  std::mt19937_64 rng(15);
  for (const auto& [widths, activation] :
       {std::pair{std::vector<int>{57, 256, 256, 24}, Activation::silu},
        std::pair{std::vector<int>{5, 33, 17, 3}, Activation::silu},
        std::pair{std::vector<int>{9, 40, 24, 6}, Activation::relu}}) {
    MlpT<double> reference(widths, activation);
    reference.initialize(rng);
    Eigen::MatrixXd input(widths.front(), 37), d_output(widths.back(), 37);
    for (Eigen::Index i = 0; i < input.size(); ++i) input(i) = 2.0 * uniform01(rng) - 1.0;
    for (Eigen::Index i = 0; i < d_output.size(); ++i) d_output(i) = 2.0 * uniform01(rng) - 1.0;
    const Eigen::MatrixXd output = reference.forward(input);
    const Eigen::MatrixXd d_input = reference.backward(d_output);
    for (KernelIsa isa : supported_sets()) {
      INFO("kernel set " << to_string(isa) << ", input width " << widths.front() << ", "
                         << to_string(activation));
      set_kernel_isa(isa);
      Mlp net(widths, activation);
      net.parameters() = reference.parameters().cast<float>();
      const Eigen::MatrixXf out = net.forward(input.cast<float>());
      const Eigen::MatrixXf din = net.backward(d_output.cast<float>());
      const auto relative = [](const auto& x, const Eigen::MatrixXd& y) {
        return (x.template cast<double>() - y).cwiseAbs().template maxCoeff<Eigen::PropagateNaN>() /
               (1.0 + y.cwiseAbs().maxCoeff<Eigen::PropagateNaN>());
      };
      CHECK(relative(out, output) < 1e-5);
      CHECK(relative(din, d_input) < 1e-5);
      CHECK(relative(net.gradient(), reference.gradient()) < 1e-5);
      Eigen::MatrixXf single, scratch[2];
      net.infer(input.col(3).cast<float>(), single, scratch);
      CHECK(relative(single, output.col(3)) < 1e-5);
    }
  }
}

TEST_CASE("kernel_sets_are_named_chosen_and_refused_with_typed_errors", "[unit]") {
  KernelSetGuard guard;
  for (KernelIsa isa : {KernelIsa::generic, KernelIsa::avx2, KernelIsa::avx512}) {
    CHECK(parse_kernel_isa(to_string(isa)) == isa);
  }
  HC_CHECK_THROWS(parse_kernel_isa("sse9"), InvalidArgument,
                  Catch::Contains("'sse9'") && Catch::Contains("avx512"));
  CHECK(kernel_isa_supported(KernelIsa::generic));
  CHECK(kernel_isa_supported(best_kernel_isa()));
  // The best named set is Highway's dynamic choice, the first of the targets tested above.
  CHECK(kernels::kernels_for(best_kernel_isa()).target == kernels::available_targets().front());
  CHECK(kernels::best_kernels().target == kernels::available_targets().front());
  set_kernel_isa(KernelIsa::generic);
  CHECK(kernel_isa() == KernelIsa::generic);
  for (KernelIsa isa : {KernelIsa::avx2, KernelIsa::avx512}) {
    if (!kernel_isa_supported(isa)) {
      HC_CHECK_THROWS(set_kernel_isa(isa), InvalidArgument, Catch::Contains(to_string(isa)));
    }
  }
}

TEST_CASE("training_is_bit_for_bit_repeatable_on_each_kernel_set", "[unit]") {
  // Same seed, same kernel set: the same bits. (Different sets differ in the last bits.)
  KernelSetGuard guard;
  for (KernelIsa isa : supported_sets()) {
    set_kernel_isa(isa);
    const auto train = [] {
      std::mt19937_64 rng(16);
      Mlp net({9, 40, 40, 4}, Activation::silu);
      net.initialize(rng);
      Adam adam(net.parameter_count(), AdamOptions{1e-3, 0.9, 0.999, 1e-8, 0.0});
      Eigen::MatrixXf input(9, 50), d_output(4, 50);
      for (int step = 0; step < 5; ++step) {
        for (Eigen::Index i = 0; i < input.size(); ++i)
          input(i) = static_cast<float>(uniform01(rng));
        d_output = net.forward(input) * 0.1f;
        net.backward_parameters(d_output);
        adam.step(net.parameters(), net.gradient());
      }
      return Eigen::VectorXf(net.parameters());
    };
    const Eigen::VectorXf first = train(), second = train();
    INFO(to_string(isa));
    CHECK(first.cwiseEqual(second).all());
  }
}

TEST_CASE("masked_kernel_accesses_are_checked_lane_by_lane_under_asan", "[unit]") {
  // ASan does not see masked loads, stores and gathers (builtins); the kernels check their
  // enabled lanes through poisoned_lane (kernels/asan_lanes.hpp). Off ASan it finds nothing.
#if defined(__SANITIZE_ADDRESS__) || defined(HANDCENTRIC_ASAN)
  std::vector<float> five(5, 1.0f);
  const float* x = five.data();
  CHECK(kernels::poisoned_lane(x, 0x1F, sizeof(float)) == nullptr);  // lanes 0..4: the buffer
  CHECK(kernels::poisoned_lane(x, 0x3F, sizeof(float)) == x + 5);    // a tail one lane too long
  CHECK(kernels::poisoned_lane(x - 1, 0x3E, sizeof(float)) ==
        nullptr);  // a shifted head: lane 0 is off
  CHECK(kernels::poisoned_lane(x - 1, 0x3F, sizeof(float)) == x - 1);  // ... unless it is on
  CHECK(kernels::poisoned_lane(x, 0x21, sizeof(float)) ==
        x + 5);  // lanes between are skipped, not the last
#else
  std::vector<float> five(5, 1.0f);
  CHECK(kernels::poisoned_lane(five.data(), 0xFFFF, sizeof(float)) == nullptr);
#endif
}
