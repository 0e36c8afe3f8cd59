#pragma once
// Adam (Kingma & Ba) with decoupled weight decay (AdamW, Loshchilov & Hutter) on one flat
// parameter vector, and gradient clipping by the global L2 norm.
#include <Eigen/Core>

namespace handcentric::policy {

struct AdamOptions {
  double learning_rate = 1e-3;
  double beta1 = 0.9;
  double beta2 = 0.999;
  double epsilon = 1e-8;
  double weight_decay = 0.0;  ///< decoupled: p -= lr * weight_decay * p
};

class Adam {
 public:
  /// Throws InvalidArgument for a non-positive learning rate, betas outside [0, 1), a negative
  /// epsilon or weight decay.
  Adam(Eigen::Index parameter_count, AdamOptions options);

  /// One update of `parameters` from gradient_scale * `gradient` (same length as the
  /// constructor's count); the scale is where clipping goes (gradient_clip_scale), so the
  /// gradient is not rewritten first.
  void step(Eigen::VectorXf& parameters, const Eigen::VectorXf& gradient,
            float gradient_scale = 1.0f);

  long long steps_taken() const { return t_; }

  /// The learning rate of the next steps (a schedule, trainer.hpp). Throws InvalidArgument for a
  /// non-positive or non-finite value.
  void set_learning_rate(double learning_rate);
  double learning_rate() const { return options_.learning_rate; }

 private:
  AdamOptions options_;
  Eigen::VectorXf m_, v_;
  long long t_ = 0;
};

/// The factor that brings `gradient`'s L2 norm down to `max_norm`: max_norm / |g| when |g| >
/// max_norm, else 1 (and 1 when max_norm is 0: no clipping). `norm`, when given, gets |g|.
float gradient_clip_scale(const Eigen::VectorXf& gradient, double max_norm, double* norm = nullptr);

/// Scales `gradient` so that its L2 norm is at most `max_norm` (0 disables); returns the norm
/// before clipping.
double clip_gradient_norm(Eigen::VectorXf& gradient, double max_norm);

}  // namespace handcentric::policy
