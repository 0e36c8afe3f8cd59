#pragma once
// The training losses and their gradients, templated on the scalar so that the same code runs
// in float (training) and in double (the finite-difference checks in tests/policy).
//
//   mse   L = 1/N sum (pred - target)^2 over all N entries,   dL/dpred = 2/N (pred - target)
//         (eq. (5) averaged over the minibatch and the action dimensions)
//   kl    L = weight/N sum 1/2 (mu^2 + exp(lv) - lv - 1),     KL(N(mu, exp(lv)) || N(0, 1))
//         dL/dmu = weight/N mu,  dL/dlv = weight/N 1/2 (exp(lv) - 1)
#include <Eigen/Core>

namespace handcentric::policy {

template <typename Scalar>
using MatrixX = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;

template <typename Scalar>
double mse_loss(const MatrixX<Scalar>& pred, const MatrixX<Scalar>& target,
                MatrixX<Scalar>& d_pred) {
  d_pred = pred - target;
  const auto n = static_cast<double>(d_pred.size());
  const double loss = static_cast<double>(d_pred.squaredNorm()) / n;
  d_pred *= static_cast<Scalar>(2.0 / n);
  return loss;
}

template <typename Scalar>
double gaussian_kl_loss(const MatrixX<Scalar>& mu, const MatrixX<Scalar>& log_var, double weight,
                        MatrixX<Scalar>& d_mu, MatrixX<Scalar>& d_log_var) {
  const auto n = static_cast<double>(mu.size());
  const auto exp_lv = log_var.array().exp();
  const double kl =
      0.5 * static_cast<double>((mu.array().square() + exp_lv - log_var.array() - Scalar(1)).sum());
  const auto scale = static_cast<Scalar>(weight / n);
  d_mu = scale * mu;
  d_log_var = (scale * Scalar(0.5) * (exp_lv - Scalar(1))).matrix();
  return weight * kl / n;
}

}  // namespace handcentric::policy
