#pragma once
// WeightAverage: the exponential moving average of the parameters over training steps, the
// weights Diffusion Policy keeps for sampling ("EMA"). After optimizer step t (t = 1, 2, ...):
//
//   d_t = min(decay, (1 + t) / (10 + t))           (warm-up: early steps are not frozen in)
//   average_1 = theta_1,   average_t = d_t average_{t-1} + (1 - d_t) theta_t
//
// The average does not touch the optimization: the iterates theta_t are the same with or without
// it. decay = 0 turns it off.
#include <Eigen/Core>

namespace handcentric::policy {

class WeightAverage {
 public:
  /// Throws InvalidArgument for a decay outside [0, 1).
  explicit WeightAverage(double decay = 0.0);

  bool active() const { return decay_ > 0.0; }
  /// Folds in the parameters after one optimizer step (nothing when inactive).
  void update(const Eigen::VectorXf& parameters);
  /// The average so far; empty before the first update.
  const Eigen::VectorXf& average() const { return average_; }
  long long updates() const { return updates_; }

 private:
  double decay_;
  Eigen::VectorXf average_;
  long long updates_ = 0;
};

}  // namespace handcentric::policy
