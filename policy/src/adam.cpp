#include "handcentric/policy/adam.hpp"

#include <cmath>
#include <string>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "kernels/kernel_set.hpp"

namespace handcentric::policy {

Adam::Adam(Eigen::Index parameter_count, AdamOptions options) : options_(options) {
  if (!(options.learning_rate > 0.0) || !(options.beta1 >= 0.0 && options.beta1 < 1.0) ||
      !(options.beta2 >= 0.0 && options.beta2 < 1.0) || !(options.epsilon >= 0.0) ||
      !(options.weight_decay >= 0.0)) {
    throw InvalidArgument(
        "Adam: learning rate " + format_number(options.learning_rate) + ", betas " +
        format_number(options.beta1) + ", " + format_number(options.beta2) + ", epsilon " +
        format_number(options.epsilon) + ", weight decay " + format_number(options.weight_decay) +
        ": use lr > 0, betas in [0, 1), epsilon >= 0, weight decay >= 0");
  }
  m_ = Eigen::VectorXf::Zero(parameter_count);
  v_ = Eigen::VectorXf::Zero(parameter_count);
}

void Adam::step(Eigen::VectorXf& parameters, const Eigen::VectorXf& gradient,
                float gradient_scale) {
  if (parameters.size() != m_.size() || gradient.size() != m_.size()) {
    throw InvalidArgument("Adam::step: " + std::to_string(parameters.size()) + " parameters and " +
                          std::to_string(gradient.size()) + " gradients, expected " +
                          std::to_string(m_.size()));
  }
  ++t_;
  const float b1 = static_cast<float>(options_.beta1);
  const float b2 = static_cast<float>(options_.beta2);
  const double bias1 = 1.0 - std::pow(options_.beta1, static_cast<double>(t_));
  const double bias2 = 1.0 - std::pow(options_.beta2, static_cast<double>(t_));
  // p -= lr / bias1 * m / (sqrt(v / bias2) + eps), the bias corrections folded into scalars.
  const float step_size = static_cast<float>(options_.learning_rate / bias1);
  const float inv_sqrt_bias2 = static_cast<float>(1.0 / std::sqrt(bias2));
  const float eps = static_cast<float>(options_.epsilon);
  kernels::AdamUpdate update;
  update.n = parameters.size();
  update.parameters = parameters.data();
  update.gradient = gradient.data();
  update.gradient_scale = gradient_scale;
  update.m = m_.data();
  update.v = v_.data();
  update.beta1 = b1;
  update.beta2 = b2;
  update.step_size = step_size;
  update.inv_sqrt_bias2 = inv_sqrt_bias2;
  update.epsilon = eps;
  update.decay = static_cast<float>(1.0 - options_.learning_rate * options_.weight_decay);  // AdamW
  kernels::active().adam(update);
}

float gradient_clip_scale(const Eigen::VectorXf& gradient, double max_norm, double* norm) {
  const double length = std::sqrt(kernels::active().squared_norm(gradient.size(), gradient.data()));
  if (norm != nullptr) *norm = length;
  return max_norm > 0.0 && length > max_norm ? static_cast<float>(max_norm / length) : 1.0f;
}

void Adam::set_learning_rate(double learning_rate) {
  if (!(learning_rate > 0.0) || !std::isfinite(learning_rate)) {
    throw InvalidArgument("Adam: learning rate " + format_number(learning_rate) +
                          ": use a finite lr > 0");
  }
  options_.learning_rate = learning_rate;
}

double clip_gradient_norm(Eigen::VectorXf& gradient, double max_norm) {
  double norm = 0.0;
  const float scale = gradient_clip_scale(gradient, max_norm, &norm);
  if (scale != 1.0f) gradient *= scale;
  return norm;
}

}  // namespace handcentric::policy
