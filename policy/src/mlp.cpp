#include "handcentric/policy/mlp.hpp"

#include <cmath>
#include <string>
#include <type_traits>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/policy/layer_watch.hpp"
#include "kernels/kernel_set.hpp"

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
  delta_.resize(layers() + 1);
}

template <typename Scalar>
Eigen::Map<const typename MlpT<Scalar>::Matrix> MlpT<Scalar>::W(int layer) const {
  return Eigen::Map<const Matrix>(parameters_.data() + offsets_[layer], widths_[layer + 1],
                                  widths_[layer]);
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

// delta *= ReLU'(z) = [z > 0]. (SiLU's derivative is in propagate(), from the kept sigmoid.)
template <typename Matrix>
void multiply_by_relu_derivative(const Matrix& z, Matrix& delta) {
  using Scalar = typename Matrix::Scalar;
  delta.array() *= (z.array() > Scalar(0)).template cast<Scalar>();
}

// The three products of a layer, on column-major storage. float runs on the dispatched kernels
// (kernels.hpp); double (the gradient checks) on Eigen.
using kernels::Op;

// out (rows x batch) = W in + b 1^T (float: then SiLU in place when `silu`, with sigmoid(z)
// into `sigmoid` when it is not null).
template <typename Scalar, typename W, typename B, typename In, typename Out>
void affine(const W& weights, const B& bias, const In& in, Out& out, bool silu = false,
            Scalar* sigmoid = nullptr) {
  out.resize(weights.rows(), in.cols());
  if constexpr (std::is_same_v<Scalar, float>) {
    kernels::Gemm problem{Op::none,
                          Op::none,
                          static_cast<int>(weights.rows()),
                          static_cast<int>(in.cols()),
                          static_cast<int>(weights.cols()),
                          weights.data(),
                          static_cast<int>(weights.rows()),
                          in.data(),
                          static_cast<int>(in.outerStride()),
                          bias.data(),
                          out.data(),
                          static_cast<int>(out.rows())};
    if (silu) {
      problem.epilogue = kernels::Epilogue::silu;
      problem.sigmoid = sigmoid;
      problem.lds = static_cast<int>(out.rows());
    }
    kernels::active().gemm(problem);
  } else {
    out.noalias() = weights * in;
    out.colwise() += bias;
  }
}

// dW (out x in) = delta a^T and db = delta 1.
template <typename Scalar, typename Delta, typename A, typename DW, typename DB>
void outer(const Delta& delta, const A& a, DW& dW, DB& db) {
  if constexpr (std::is_same_v<Scalar, float>) {
    kernels::Gemm product{Op::none,
                          Op::transpose,
                          static_cast<int>(delta.rows()),
                          static_cast<int>(a.rows()),
                          static_cast<int>(delta.cols()),
                          delta.data(),
                          static_cast<int>(delta.rows()),
                          a.data(),
                          static_cast<int>(a.rows()),
                          nullptr,
                          dW.data(),
                          static_cast<int>(dW.rows())};
    product.a_row_sums = db.data();  // added up while the product packs delta
    kernels::active().gemm(product);
  } else {
    dW.noalias() = delta * a.transpose();
    db.noalias() = delta.rowwise().sum();
  }
}

// out (in x batch) = W^T delta (float: then times SiLU'(z) of the layer below, s + a (1 - s),
// when `activation` and `sigmoid`, that layer's a and s, are not null).
template <typename Scalar, typename W, typename Delta, typename Out>
void transposed(const W& weights, const Delta& delta, Out& out, const Scalar* activation = nullptr,
                Scalar* sigmoid = nullptr) {
  out.resize(weights.cols(), delta.cols());
  if constexpr (std::is_same_v<Scalar, float>) {
    kernels::Gemm problem{Op::transpose,
                          Op::none,
                          static_cast<int>(weights.cols()),
                          static_cast<int>(delta.cols()),
                          static_cast<int>(weights.rows()),
                          weights.data(),
                          static_cast<int>(weights.rows()),
                          delta.data(),
                          static_cast<int>(delta.rows()),
                          nullptr,
                          out.data(),
                          static_cast<int>(out.rows())};
    if (activation != nullptr) {
      problem.epilogue = kernels::Epilogue::silu_derivative;
      problem.activation = activation;
      problem.sigmoid = sigmoid;
      problem.lds = static_cast<int>(out.rows());
    }
    kernels::active().gemm(problem);
  } else {
    out.noalias() = weights.transpose() * delta;
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
    const bool hidden = l + 1 < layers();
    if constexpr (std::is_same_v<Scalar, float>) {
      if (hidden && activation_ == Activation::silu) {
        // SiLU fused into the product; sigmoid(z) kept for backward() (one exp per unit, not
        // two), and z itself is not kept: SiLU' = s + a (1 - s).
        sigmoid_[l].resize(widths_[l + 1], input.cols());
        affine<Scalar>(W(l), b(l), a_[l], a_[l + 1], true, sigmoid_[l].data());
        continue;
      }
    }
    affine<Scalar>(W(l), b(l), a_[l], z_[l]);
    if (hidden) {
      if (activation_ == Activation::silu) {
        // double (the gradient checks): z kept, sigmoid(z) for backward().
        sigmoid_[l].resize(z_[l].rows(), z_[l].cols());
        a_[l + 1].resize(z_[l].rows(), z_[l].cols());
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
const typename MlpT<Scalar>::Matrix& MlpT<Scalar>::backward(
    const Eigen::Ref<const Matrix>& d_output) {
  propagate(d_output, true);
  return delta_[0];
}

template <typename Scalar>
void MlpT<Scalar>::backward_parameters(const Eigen::Ref<const Matrix>& d_output) {
  propagate(d_output, false);
}

template <typename Scalar>
void MlpT<Scalar>::propagate(const Eigen::Ref<const Matrix>& d_output, bool input_gradient) {
  const Eigen::Index batch = a_[0].cols();
  if (d_output.rows() != output_size() || d_output.cols() != batch) {
    throw InvalidArgument("Mlp::backward: d_output is " + std::to_string(d_output.rows()) + "x" +
                          std::to_string(d_output.cols()) + ", expected " +
                          std::to_string(output_size()) + "x" + std::to_string(batch) +
                          " (call forward() first)");
  }
  delta_[layers()] = d_output;
  // float with SiLU: the product W^T delta that hands delta to the layer below also multiplies
  // it by that layer's SiLU' (the GEMM's epilogue), so the derivative is already applied here.
  constexpr bool kFloat = std::is_same_v<Scalar, float>;
  const bool fused_derivative = kFloat && activation_ == Activation::silu;
  for (int l = layers() - 1; l >= 0; --l) {
    Matrix& delta = delta_[l + 1];
    if (l + 1 < layers() && !fused_derivative) {
      if (activation_ == Activation::silu) {
        // SiLU'(z) = s (1 + z (1 - s)) = s + a (1 - s), s = sigmoid(z) kept by forward().
        if constexpr (kFloat) {
          kernels::active().silu_backward(delta.size(), a_[l + 1].data(), sigmoid_[l].data(),
                                          delta.data());
        } else {
          const auto s = sigmoid_[l].array();
          delta.array() *= s * (Scalar(1) + z_[l].array() * (Scalar(1) - s));
        }
      } else {
        multiply_by_relu_derivative(z_[l], delta);
      }
    }
    const Eigen::Index n = static_cast<Eigen::Index>(widths_[l + 1]) * widths_[l];
    Eigen::Map<Matrix> dW(gradient_.data() + offsets_[l], widths_[l + 1], widths_[l]);
    Eigen::Map<Vector> db(gradient_.data() + offsets_[l] + n, widths_[l + 1]);
    outer<Scalar>(delta, a_[l], dW, db);
    if (l == 0 && !input_gradient) break;
    if (fused_derivative && l > 0) {
      transposed<Scalar>(W(l), delta, delta_[l], a_[l].data(), sigmoid_[l - 1].data());
    } else {
      transposed<Scalar>(W(l), delta, delta_[l]);
    }
  }
}

template <typename Scalar>
void MlpT<Scalar>::infer(const Eigen::Ref<const Matrix>& input, Matrix& output,
                         Matrix (&scratch)[2]) const {
  if (input.rows() != input_size()) {
    throw InvalidArgument("Mlp input has " + std::to_string(input.rows()) + " rows, expected " +
                          std::to_string(input_size()));
  }
  // Each layer's output goes to this thread's watches, if any (layer_watch.hpp).
  if (layers() == 1) {
    affine<Scalar>(W(0), b(0), input, output);
    watch_layer("mlp.layer", 1, output);
    return;
  }
  const bool fused = std::is_same_v<Scalar, float> && activation_ == Activation::silu;
  affine<Scalar>(W(0), b(0), input, scratch[0], fused);
  int current = 0;
  for (int l = 1; l < layers(); ++l) {
    if (!fused) activate(activation_, scratch[current], scratch[current]);
    watch_layer("mlp.layer", l, scratch[current]);
    const bool hidden = l + 1 < layers();
    Matrix& next = hidden ? scratch[1 - current] : output;
    affine<Scalar>(W(l), b(l), scratch[current], next, fused && hidden);
    current = 1 - current;
  }
  watch_layer("mlp.layer", layers(), output);
}

template class MlpT<float>;
template class MlpT<double>;

}  // namespace handcentric::policy
