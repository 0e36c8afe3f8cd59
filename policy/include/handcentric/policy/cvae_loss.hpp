#pragma once
// The CVAE objective (App. B ablation) and its gradients through the reparameterization, for
// float (training) and double (the finite-difference check in tests/policy):
//
//   [mu; logvar] = E([a; o]), logvar clamped to +-kCvaeLogVarClamp (no gradient where clamped)
//   z = mu + exp(logvar / 2) eps,   a_hat = D([z; o])
//   L = 1/(B D) sum |a_hat - a|^2 + beta / (B Z) sum KL(N(mu, exp(logvar)) || N(0, I)) (losses.hpp)
#include "handcentric/policy/losses.hpp"
#include "handcentric/policy/mlp.hpp"

namespace handcentric::policy {

constexpr double kCvaeLogVarClamp = 10.0;

template <typename Scalar>
struct CvaeBuffers {
  MatrixX<Scalar> encoder_input, decoder_input, raw_log_var, log_var, sigma, d_a, d_mu, d_log_var,
      d_stats;
};

/// L for normalized actions `a` (D x B), normalized observations `o` and standard normals
/// `noise` (Z x B); sets encoder.gradient() and decoder.gradient() to dL/dtheta.
template <typename Scalar>
double cvae_loss_and_gradients(MlpT<Scalar>& encoder, MlpT<Scalar>& decoder,
                               const MatrixX<Scalar>& a, const MatrixX<Scalar>& o,
                               const MatrixX<Scalar>& noise, double kl_weight,
                               CvaeBuffers<Scalar>& buffers);

}  // namespace handcentric::policy
