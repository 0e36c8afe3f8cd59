// Normalizer: both forms of normalize (in place, and into another matrix in one pass) give each
// value (x - mean) * (1 / scale) rounded after the subtraction and after the product, the bits
// training has always seen; a form rounded otherwise (x / scale - mean / scale) is seen.
#include <catch2/catch.hpp>

#include <random>

#include "handcentric/core/errors.hpp"
#include "handcentric/policy/normalizer.hpp"

using namespace handcentric;
using namespace handcentric::policy;

TEST_CASE("normalizing_in_place_or_into_a_matrix_gives_the_same_bits", "[unit]") {
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> uniform(-3.0, 3.0);
  Eigen::MatrixXd data(7, 40);
  for (Eigen::Index i = 0; i < data.size(); ++i) data(i) = uniform(rng) * (1 + i % 7);
  const Normalizer normalizer = Normalizer::fit(data);
  const Eigen::MatrixXf columns = data.cast<float>();
  Eigen::MatrixXf expected(columns.rows(), columns.cols()), otherwise = expected;
  for (Eigen::Index j = 0; j < columns.cols(); ++j) {
    for (Eigen::Index i = 0; i < columns.rows(); ++i) {
      const float mean = static_cast<float>(normalizer.mean()[i]);
      const float inverse = static_cast<float>(1.0 / normalizer.scale()[i]);
      const float centred = columns(i, j) - mean;
      expected(i, j) = centred * inverse;
      const float scaled = columns(i, j) * inverse, shift = mean * inverse;
      otherwise(i, j) = scaled - shift;
    }
  }
  Eigen::MatrixXf in_place = columns, into(3, 2);
  normalizer.normalize(in_place);
  normalizer.normalize(columns, into);
  CHECK(in_place == expected);
  CHECK(into == expected);
  // The check can fail: another order of the roundings differs somewhere.
  CHECK(otherwise != expected);
  CHECK_THROWS_AS(normalizer.normalize(columns.topRows(6), into), InvalidArgument);
}
