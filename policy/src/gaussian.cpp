#include "handcentric/policy/gaussian.hpp"

#include <cstdint>
#include <vector>

#include "box_muller.hpp"

namespace handcentric::policy {

void fill_standard_normal(std::mt19937_64& rng, Eigen::Ref<Eigen::MatrixXf> out) {
  // One 64-bit draw per pair of normals (box_muller.hpp).
  thread_local std::vector<std::uint64_t> bits;
  thread_local std::vector<float> values;
  const Eigen::Index n = out.size(), pairs = (n + 1) / 2;
  bits.resize(static_cast<std::size_t>(pairs));
  for (std::uint64_t& b : bits) b = rng();
  if (n % 2 == 0 && (out.cols() <= 1 || out.outerStride() == out.rows())) {
    // Contiguous and whole pairs (the training noise): the pairs go straight into `out`.
    box_muller_pairs(pairs, bits.data(), out.data());
    return;
  }
  values.resize(static_cast<std::size_t>(2 * pairs));
  box_muller_pairs(pairs, bits.data(), values.data());
  // Ref<MatrixXf> has an inner stride of 1 but may have an outer stride: walk column by column.
  Eigen::Index k = 0;
  for (Eigen::Index j = 0; j < out.cols(); ++j) {
    for (Eigen::Index i = 0; i < out.rows(); ++i) out(i, j) = values[static_cast<std::size_t>(k++)];
  }
}

}  // namespace handcentric::policy
