// The seeded normal noise (policy/gaussian.hpp): the Box-Muller pair of each 64-bit draw against
// the formula in double, and fill_standard_normal's use of it.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "box_muller.hpp"
#include "handcentric/policy/gaussian.hpp"

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
}
