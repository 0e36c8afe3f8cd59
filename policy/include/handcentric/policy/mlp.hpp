#pragma once
// Mlp: a multi-layer perceptron with hand-written backprop (Sec. 4.1: "a simple MLP").
//
//   z_l = W_l a_{l-1} + b_l,   a_l = act(z_l) (hidden layers),   output = z_L (linear)
//
// Column-major batches: an input is (input_size x B), one sample per column, so every layer
// is one GEMM over the whole minibatch. All parameters live in ONE flat vector (W_1, b_1,
// W_2, b_2, ...; each W column-major) so that Adam, clipping and model files see one array.
// Scalar = float for training and sampling, on the run-time dispatched kernels of kernels.hpp;
// double (Eigen) for the finite-difference gradient checks.
#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <vector>

#include "handcentric/policy/config.hpp"
#include "handcentric/policy/kernels.hpp"

namespace handcentric::policy {

template <typename Scalar>
class MlpT {
 public:
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;

  MlpT() = default;
  /// widths = {input, hidden..., output}; at least {input, output}. Throws InvalidArgument for
  /// fewer than two widths or a width < 1. Parameters start at zero: call initialize().
  MlpT(std::vector<int> widths, Activation activation);

  /// PyTorch's default: W, b uniform in +-1/sqrt(fan_in), from `rng` (same seed, same bits).
  void initialize(std::mt19937_64& rng);

  int input_size() const { return widths_.front(); }
  int output_size() const { return widths_.back(); }
  const std::vector<int>& widths() const { return widths_; }
  Activation activation() const { return activation_; }
  Eigen::Index parameter_count() const { return parameters_.size(); }

  Vector& parameters() { return parameters_; }
  const Vector& parameters() const { return parameters_; }
  /// d loss / d parameters, written by backward().
  const Vector& gradient() const { return gradient_; }

  /// Training forward pass: keeps the activations for backward(). Returns (output x B).
  const Matrix& forward(const Eigen::Ref<const Matrix>& input);

  /// Backward pass from d loss / d output (output x B) of the last forward(): sets gradient()
  /// and returns d loss / d input (input x B).
  const Matrix& backward(const Eigen::Ref<const Matrix>& d_output);
  /// backward() without d loss / d input: sets gradient() only (one product less).
  void backward_parameters(const Eigen::Ref<const Matrix>& d_output);

  /// Inference into `output` without touching the training caches; `scratch` holds two
  /// buffers that are reused (no allocation once they have the right size).
  void infer(const Eigen::Ref<const Matrix>& input, Matrix& output, Matrix (&scratch)[2]) const;

 private:
  int layers() const { return static_cast<int>(widths_.size()) - 1; }
  Eigen::Map<const Matrix> W(int layer) const;
  Eigen::Map<const Vector> b(int layer) const;
  /// The backward pass: delta_[l + 1] = d loss / d z_l, and delta_[0] = d loss / d input when
  /// input_gradient.
  void propagate(const Eigen::Ref<const Matrix>& d_output, bool input_gradient);

  std::vector<int> widths_;
  Activation activation_ = Activation::silu;
  std::vector<Eigen::Index> offsets_;  ///< start of W_l in parameters_; b_l follows W_l
  Vector parameters_;
  Vector gradient_;
  std::vector<Matrix> z_;        ///< pre-activations of the last forward()
  std::vector<Matrix> sigmoid_;  ///< SiLU only: sigmoid(z_[l]) of the last forward()
  std::vector<Matrix> a_;        ///< a_[0] = input, a_[l] = act(z_[l-1])
  /// One buffer per layer boundary, each of one size: no reallocation from step to step
  /// (delta_[0] is d loss / d input, delta_[l + 1] d loss / d z_l).
  std::vector<Matrix> delta_;
};

using Mlp = MlpT<float>;

}  // namespace handcentric::policy
