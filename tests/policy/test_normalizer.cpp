// Normalizer: both forms of normalize (in place, and into another matrix in one pass) give each
// value (x - mean) * (1 / scale) rounded after the subtraction and after the product, the bits
// training has always seen; a form rounded otherwise (x / scale - mean / scale) is seen.
#include <catch2/catch.hpp>

#include <random>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/policy/normalizer.hpp"

using namespace handcentric;
using namespace handcentric::policy;

namespace {

// Training data whose rows have different scales (row i up to 3 (1 + i)).
Eigen::MatrixXd scaled_data(Eigen::Index rows, Eigen::Index cols, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(-3.0, 3.0);
  Eigen::MatrixXd data(rows, cols);
  for (Eigen::Index i = 0; i < data.size(); ++i) data(i) = uniform(rng) * (1 + i % rows);
  return data;
}

}  // namespace

TEST_CASE("normalizing_in_place_or_into_a_matrix_gives_the_same_bits", "[unit]") {
  const Eigen::MatrixXd data = scaled_data(7, 40, 31);
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

// normalize(set, picked, out): columns drawn from a set (repeated, in any order) normalized
// straight into out, the bits of the same columns copied out and normalized; an index outside
// the set is refused with the index and the set's size.
TEST_CASE("normalizing_picked_columns_of_a_set_gives_the_bits_of_normalizing_a_copy", "[unit]") {
  const Eigen::MatrixXd data = scaled_data(5, 30, 37);
  const Normalizer normalizer = Normalizer::fit(data);
  const Eigen::MatrixXf set = data.cast<float>();
  const std::vector<Eigen::Index> picked = {29, 0, 7, 7, 13, 2};
  Eigen::MatrixXf copy(set.rows(), static_cast<Eigen::Index>(picked.size()));
  for (std::size_t j = 0; j < picked.size(); ++j)
    copy.col(static_cast<Eigen::Index>(j)) = set.col(picked[j]);
  Eigen::MatrixXf expected, out(1, 1);
  normalizer.normalize(copy, expected);
  normalizer.normalize(set, picked, out);
  CHECK(out == expected);
  // The check can fail: another pick gives other columns.
  std::vector<Eigen::Index> other = picked;
  other[3] = 8;
  normalizer.normalize(set, other, out);
  CHECK(out != expected);
  const std::vector<Eigen::Index> outside = {0, 30};
  CHECK_THROWS_WITH(normalizer.normalize(set, outside, out),
                    Catch::Contains("column 30 picked from a set of 30 columns"));
  CHECK_THROWS_AS(normalizer.normalize(set.topRows(4), picked, out), InvalidArgument);
}
