#include "handcentric/policy/mlp.hpp"

#include <cmath>
#include <string>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/sampling.hpp"

namespace handcentric::policy {

template <typename Scalar>
MlpT<Scalar>::MlpT(std::vector<int> widths, Activation activation)
    : widths_(std::move(widths)), activation_(activation) {
  if (widths_.size() < 2) throw InvalidArgument("Mlp needs at least {input, output} widths");
  Eigen::Index count = 0;
  for (std::size_t l = 0; l < widths_.size(); ++l) {
    if (widths_[l] < 1) {
      throw InvalidArgument("Mlp width " + std::to_string(l) + " is " + std::to_string(widths_[l]) +
                            ": every layer needs at least one unit");
    }
    if (l + 1 < widths_.size()) {
      offsets_.push_back(count);
      count += static_cast<Eigen::Index>(widths_[l + 1]) * (widths_[l] + 1);
    }
  }
  parameters_ = Vector::Zero(count);
  gradient_ = Vector::Zero(count);
  z_.resize(layers());
  sigmoid_.resize(layers());
  a_.resize(layers() + 1);
}

template <typename Scalar>
Eigen::Map<const typename MlpT<Scalar>::Matrix> MlpT<Scalar>::W(int layer) const {
  return Eigen::Map<const Matrix>(parameters_.data() + offsets_[layer], widths_[layer + 1], widths_[layer]);
}

template <typename Scalar>
Eigen::Map<const typename MlpT<Scalar>::Vector> MlpT<Scalar>::b(int layer) const {
  const Eigen::Index n = static_cast<Eigen::Index>(widths_[layer + 1]) * widths_[layer];
  return Eigen::Map<const Vector>(parameters_.data() + offsets_[layer] + n, widths_[layer + 1]);
}

template <typename Scalar>
void MlpT<Scalar>::initialize(std::mt19937_64& rng) {
  for (int l = 0; l < layers(); ++l) {
    const double bound = 1.0 / std::sqrt(static_cast<double>(widths_[l]));
    const Eigen::Index n = static_cast<Eigen::Index>(widths_[l + 1]) * (widths_[l] + 1);
    for (Eigen::Index i = 0; i < n; ++i) {
      parameters_[offsets_[l] + i] = static_cast<Scalar>(bound * (2.0 * uniform01(rng) - 1.0));
    }
  }
}

namespace {

// a = act(z), elementwise. SiLU(z) = z sigmoid(z); ReLU(z) = max(z, 0).
template <typename Matrix>
void activate(Activation activation, const Matrix& z, Matrix& a) {
  using Scalar = typename Matrix::Scalar;
  if (activation == Activation::silu) {
    a.array() = z.array() / (Scalar(1) + (-z.array()).exp());
  } else {
    a.array() = z.array().max(Scalar(0));
  }
}

// delta *= act'(z). SiLU' = s (1 + z (1 - s)) with s = sigmoid(z); ReLU' = [z > 0].
template <typename Matrix>
void multiply_by_derivative(Activation activation, const Matrix& z, Matrix& delta) {
  using Scalar = typename Matrix::Scalar;
  if (activation == Activation::silu) {
    const auto s = Scalar(1) / (Scalar(1) + (-z.array()).exp());
    delta.array() *= s * (Scalar(1) + z.array() * (Scalar(1) - s));
  } else {
    delta.array() *= (z.array() > Scalar(0)).template cast<Scalar>();
  }
}

}  // namespace

template <typename Scalar>
const typename MlpT<Scalar>::Matrix& MlpT<Scalar>::forward(const Eigen::Ref<const Matrix>& input) {
  if (input.rows() != input_size()) {
    throw InvalidArgument("Mlp input has " + std::to_string(input.rows()) + " rows, expected " +
                          std::to_string(input_size()));
  }
  a_[0] = input;
  for (int l = 0; l < layers(); ++l) {
    z_[l].noalias() = W(l) * a_[l];
    z_[l].colwise() += b(l);
    if (l + 1 < layers()) {
      if (activation_ == Activation::silu) {
        // Keep sigmoid(z) for backward(): one exp per unit instead of two.
        sigmoid_[l].resize(z_[l].rows(), z_[l].cols());
        sigmoid_[l].array() = Scalar(1) / (Scalar(1) + (-z_[l].array()).exp());
        a_[l + 1].array() = z_[l].array() * sigmoid_[l].array();
      } else {
        a_[l + 1].resize(z_[l].rows(), z_[l].cols());
        activate(activation_, z_[l], a_[l + 1]);
      }
    }
  }
  return z_[layers() - 1];
}

template <typename Scalar>
const typename MlpT<Scalar>::Matrix& MlpT<Scalar>::backward(const Eigen::Ref<const Matrix>& d_output) {
  const Eigen::Index batch = a_[0].cols();
  if (d_output.rows() != output_size() || d_output.cols() != batch) {
    throw InvalidArgument("Mlp::backward: d_output is " + std::to_string(d_output.rows()) + "x" +
                          std::to_string(d_output.cols()) + ", expected " + std::to_string(output_size()) +
                          "x" + std::to_string(batch) + " (call forward() first)");
  }
  int current = 0;
  delta_[current] = d_output;
  for (int l = layers() - 1; l >= 0; --l) {
    Matrix& delta = delta_[current];
    if (l + 1 < layers()) {
      if (activation_ == Activation::silu) {
        // SiLU'(z) = s (1 + z (1 - s)), s = sigmoid(z) from forward().
        const auto s = sigmoid_[l].array();
        delta.array() *= s * (Scalar(1) + z_[l].array() * (Scalar(1) - s));
      } else {
        multiply_by_derivative(activation_, z_[l], delta);
      }
    }
    const Eigen::Index n = static_cast<Eigen::Index>(widths_[l + 1]) * widths_[l];
    Eigen::Map<Matrix> dW(gradient_.data() + offsets_[l], widths_[l + 1], widths_[l]);
    Eigen::Map<Vector> db(gradient_.data() + offsets_[l] + n, widths_[l + 1]);
    dW.noalias() = delta * a_[l].transpose();
    db.noalias() = delta.rowwise().sum();
    delta_[1 - current].noalias() = W(l).transpose() * delta;
    current = 1 - current;
  }
  return delta_[current];
}

template <typename Scalar>
void MlpT<Scalar>::infer(const Eigen::Ref<const Matrix>& input, Matrix& output, Matrix (&scratch)[2]) const {
  if (input.rows() != input_size()) {
    throw InvalidArgument("Mlp input has " + std::to_string(input.rows()) + " rows, expected " +
                          std::to_string(input_size()));
  }
  if (layers() == 1) {
    output.noalias() = W(0) * input;
    output.colwise() += b(0);
    return;
  }
  scratch[0].noalias() = W(0) * input;
  scratch[0].colwise() += b(0);
  int current = 0;
  for (int l = 1; l < layers(); ++l) {
    activate(activation_, scratch[current], scratch[current]);
    Matrix& next = l + 1 < layers() ? scratch[1 - current] : output;
    next.noalias() = W(l) * scratch[current];
    next.colwise() += b(l);
    current = 1 - current;
  }
}

template class MlpT<float>;
template class MlpT<double>;

}  // namespace handcentric::policy
