// The seeded normal noise (policy/gaussian.hpp): the Box-Muller pair of each 64-bit draw against
// the formula in double, and fill_standard_normal's use of it; the vector kernels against libm
// bit for bit.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "box_muller.hpp"
#include "handcentric/policy/gaussian.hpp"
#include "kernels/kernel_set.hpp"

using namespace handcentric::policy;

TEST_CASE("box_muller_pairs_match_the_formula_in_double", "[unit]") {
  // Including the extremes of both 24-bit fields; `skip` plants a fault in the reference (the
  // pair taken from the next draw), which the check must catch.
  std::mt19937_64 rng(17);
  std::vector<std::uint64_t> bits(
      71);  // one more than the most pairs: the shifted reference reads i + 1
  for (std::uint64_t& b : bits) b = rng();
  bits[0] = 0;                             // u1 = 2^-24 (the largest radius), u2 = 0
  bits[1] = ~std::uint64_t{0};             // u1 = 1 (radius 0), u2 = 1 - 2^-24
  bits[2] = std::uint64_t{0x400000} << 8;  // u2 = 1/4 exactly: a quadrant boundary
  for (std::ptrdiff_t pairs : {1, 7, 70}) {
    std::vector<float> out(2 * pairs + 1, 99.0f);
    box_muller_pairs(pairs, bits.data(), out.data());
    double worst = 0.0, worst_shifted = 0.0;
    for (std::ptrdiff_t i = 0; i < pairs; ++i) {
      for (int skip : {0, 1}) {
        const std::uint64_t draw = bits[static_cast<std::size_t>(i + skip)];
        const double u1 = (BoxMuller::high24(draw) + 1.0) * 0x1.0p-24;
        const double u2 = BoxMuller::low24(draw) * 0x1.0p-24;
        const double radius = std::sqrt(-2.0 * std::log(u1)), angle = 2.0 * M_PI * u2;
        const double error = std::max(std::abs(out[2 * i] - radius * std::cos(angle)),
                                      std::abs(out[2 * i + 1] - radius * std::sin(angle)));
        (skip == 0 ? worst : worst_shifted) = std::max(skip == 0 ? worst : worst_shifted, error);
      }
    }
    INFO("pairs " << pairs);
    CHECK(worst < 3e-6);
    CHECK(worst_shifted > 1e-2);
    CHECK(out[2 * pairs] == 99.0f);  // nothing written past the end
  }
}

TEST_CASE("fill_standard_normal_is_seeded_and_column_by_column", "[unit]") {
  std::mt19937_64 a(5), b(5);
  Eigen::MatrixXf outer = Eigen::MatrixXf::Constant(7, 4, 99.0f);
  fill_standard_normal(a, outer.topRows(5));  // an outer stride: rows 5 and 6 stay untouched
  std::vector<std::uint64_t> bits(10);
  for (std::uint64_t& x : bits) x = b();
  std::vector<float> pairs(20);
  box_muller_pairs(10, bits.data(), pairs.data());
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 7; ++i)
      CHECK(outer(i, j) == (i < 5 ? pairs[static_cast<std::size_t>(i + 5 * j)] : 99.0f));
  }
  // Contiguous, with an even count (written in place) and an odd one (through the buffer): the
  // same values in the same order.
  for (int rows : {4, 5}) {
    std::mt19937_64 c(5);
    Eigen::MatrixXf whole = Eigen::MatrixXf::Constant(rows, 4, 99.0f);
    fill_standard_normal(c, whole);
    INFO(rows << " rows");
    for (int k = 0; k < rows * 4; ++k) CHECK(whole.data()[k] == pairs[static_cast<std::size_t>(k)]);
  }
}

namespace {

// libm's functions through pointers the compiler cannot see through, so neither call is merged
// into the other (GCC turns sinf and cosf of one argument into sincosf): the kernels must equal
// all three, whichever of them the scalar code was compiled to.
float (*volatile g_logf)(float) = logf;
float (*volatile g_cosf)(float) = cosf;
float (*volatile g_sinf)(float) = sinf;
void (*volatile g_sincosf)(float, float*, float*) = sincosf;

std::uint32_t bits_of(float x) {
  std::uint32_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}

struct BoxMullerSweep {
  std::int64_t radius_mismatches = 0, angle_mismatches = 0, checked = 0;
};

// Every `stride`-th value of hi (with lo fixed) and of lo (with hi fixed), and the last value of
// each, through `set`'s parts with `constants`, against libm bit for bit. Stride 1 is all 2^24
// of each.
BoxMullerSweep sweep_box_muller(const kernels::KernelSet& set, const LibmFloatConstants& constants,
                                std::uint32_t stride) {
  BoxMullerSweep sweep;
  constexpr std::uint32_t kValues = 1u << 24, kChunk = 1u << 14;
  std::vector<std::uint64_t> draws;
  std::vector<float> radius(kChunk), cosine(kChunk), sine(kChunk);
  for (bool angles : {false, true}) {
    for (std::uint32_t start = 0; start < kValues; start += kChunk * stride) {
      draws.clear();
      for (std::uint32_t v = start; v < kValues && draws.size() < kChunk; v += stride) {
        // The other field fixed at a value with no special case.
        draws.push_back(angles ? (std::uint64_t{0x9E3779} << 40) | (std::uint64_t{v} << 8)
                               : (std::uint64_t{v} << 40) | (std::uint64_t{0x7F4A7C} << 8));
      }
      // The last value of the field, 2^24 - 1, when the stride passes over it.
      if (start + kChunk * stride >= kValues && (kValues - 1) % stride != 0)
        draws.push_back(angles ? (std::uint64_t{0x9E3779} << 40) | (std::uint64_t{kValues - 1} << 8)
                               : (std::uint64_t{kValues - 1} << 40));
      const auto n = static_cast<std::ptrdiff_t>(draws.size());
      radius.resize(draws.size());
      cosine.resize(draws.size());
      sine.resize(draws.size());
      set.box_muller_parts(n, draws.data(), radius.data(), cosine.data(), sine.data(), constants);
      for (std::ptrdiff_t i = 0; i < n; ++i) {
        const std::uint64_t draw = draws[static_cast<std::size_t>(i)];
        if (!angles) {
          const float u1 = (BoxMuller::high24(draw) + 1) * BoxMuller::kTwoPow24Inverse;
          const float expected = std::sqrt(-2.0f * g_logf(u1));
          sweep.radius_mismatches += bits_of(radius[i]) != bits_of(expected);
        } else {
          const float u2 = BoxMuller::low24(draw) * BoxMuller::kTwoPow24Inverse;
          const float angle = 2.0f * std::numbers::pi_v<float> * u2;
          float s = 0, c = 0;
          g_sincosf(angle, &s, &c);
          const std::uint32_t cb = bits_of(cosine[i]), sb = bits_of(sine[i]);
          sweep.angle_mismatches += cb != bits_of(g_cosf(angle)) || sb != bits_of(g_sinf(angle)) ||
                                    cb != bits_of(c) || sb != bits_of(s);
        }
        ++sweep.checked;
      }
    }
  }
  return sweep;
}

std::vector<std::pair<std::string, const kernels::KernelSet*>> every_kernel_set() {
  std::vector<std::pair<std::string, const kernels::KernelSet*>> sets;
  for (std::int64_t target : kernels::available_targets())
    sets.emplace_back(kernels::target_name(target), &kernels::kernels_of_target(target));
  return sets;
}

// The stride of the unit test: prime, so consecutive values visit every residue of the table
// index (bits 19..22 of the float) and every binade of u1; 2 x 2^24 / 97 = 346k values a set.
constexpr std::uint32_t kUnitStride = 97;

}  // namespace

TEST_CASE("box_muller_kernels_equal_libm_bit_for_bit_on_a_stride_of_all_inputs", "[unit]") {
  for (const auto& [name, set] : every_kernel_set()) {
    const BoxMullerSweep sweep = sweep_box_muller(*set, kGlibcFloatConstants, kUnitStride);
    INFO("kernel set " << name << ", " << sweep.checked << " values");
    CHECK(sweep.checked > 340000);
    CHECK(sweep.radius_mismatches == 0);
    CHECK(sweep.angle_mismatches == 0);
    CHECK(box_muller_kernel_agrees_with_libm(*set, kGlibcFloatConstants));
  }
}

TEST_CASE("box_muller_kernels_equal_libm_bit_for_bit_on_all_2_24_inputs_of_each_field",
          "[experiment]") {
  // The exhaustive form of the unit test: 2 x 2^24 values a set, 0.3 s a set in Release, but
  // many times that in the sanitizer build (-O1), which runs the [unit] cases.
  for (const auto& [name, set] : every_kernel_set()) {
    const BoxMullerSweep sweep = sweep_box_muller(*set, kGlibcFloatConstants, 1);
    INFO("kernel set " << name);
    CHECK(sweep.checked == 2 * (std::int64_t{1} << 24));
    CHECK(sweep.radius_mismatches == 0);
    CHECK(sweep.angle_mismatches == 0);
  }
}

TEST_CASE("box_muller_checks_catch_a_coefficient_off_by_2_to_the_minus_20", "[unit]") {
  // Planted faults: a coefficient of logf's polynomial, of the sine's and of the cosine's, each
  // off by 2^-20 of itself. The vector sets must then differ from libm in the sweep and in the
  // run-time probes (so the library would fall back to libm); the scalar sets ignore the
  // constants. Not the last bit: a double coefficient one ulp off moves a float result in about
  // one input in 2^29 (where the double lands within 2^-29 ulp of a rounding midpoint), which no
  // sweep of 2^24 inputs is sure to see, and which then cannot change a trained bit either.
  const auto off = [](double x) { return x * (1.0 + 0x1p-20); };
  std::vector<std::pair<std::string, LibmFloatConstants>> faults;
  LibmFloatConstants fault = kGlibcFloatConstants;
  fault.log_poly[2] = off(fault.log_poly[2]);
  faults.emplace_back("logf A[2]", fault);
  fault = kGlibcFloatConstants;
  fault.sin_poly[0] = off(fault.sin_poly[0]);
  faults.emplace_back("sinf s1", fault);
  fault = kGlibcFloatConstants;
  fault.cos_poly[1] = off(fault.cos_poly[1]);
  faults.emplace_back("cosf c1", fault);
  for (const auto& [name, set] : every_kernel_set()) {
    const bool vector = set->box_muller_parts != &box_muller_parts_libm;
    for (const auto& [what, constants] : faults) {
      const BoxMullerSweep sweep = sweep_box_muller(*set, constants, kUnitStride);
      INFO("kernel set " << name << ", fault in " << what);
      CHECK((sweep.radius_mismatches + sweep.angle_mismatches > 0) == vector);
      CHECK(box_muller_kernel_agrees_with_libm(*set, constants) == !vector);
    }
  }
}

TEST_CASE("box_muller_pairs_equal_the_scalar_libm_pairs_on_every_kernel_set", "[unit]") {
  // The interleaved pairs of the kernels against the scalar code's, at lengths with and without
  // a tail, and fill_standard_normal on each set against the scalar pairs.
  std::mt19937_64 rng(29);
  std::vector<std::uint64_t> bits(1000);
  for (std::uint64_t& b : bits) b = rng();
  for (const auto& [name, set] : every_kernel_set()) {
    for (std::ptrdiff_t pairs : {1, 3, 8, 16, 17, 1000}) {
      std::vector<float> vector_out(2 * pairs + 1, 99.0f), libm_out(2 * pairs);
      set->box_muller(pairs, bits.data(), vector_out.data(), kGlibcFloatConstants);
      box_muller_pairs_libm(pairs, bits.data(), libm_out.data());
      INFO("kernel set " << name << ", " << pairs << " pairs");
      CHECK(std::memcmp(vector_out.data(), libm_out.data(), libm_out.size() * sizeof(float)) == 0);
      CHECK(vector_out[2 * pairs] == 99.0f);  // nothing written past the end
    }
  }
}
