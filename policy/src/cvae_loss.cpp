#include "handcentric/policy/cvae_loss.hpp"

namespace handcentric::policy {

template <typename Scalar>
double cvae_loss_and_gradients(MlpT<Scalar>& encoder, MlpT<Scalar>& decoder,
                               const MatrixX<Scalar>& a, const MatrixX<Scalar>& o,
                               const MatrixX<Scalar>& noise, double kl_weight,
                               CvaeBuffers<Scalar>& b) {
  const Eigen::Index batch = a.cols(), da = a.rows(), dobs = o.rows(), Z = noise.rows();
  const auto clamp = static_cast<Scalar>(kCvaeLogVarClamp);
  b.encoder_input.resize(da + dobs, batch);
  b.encoder_input.topRows(da) = a;
  b.encoder_input.bottomRows(dobs) = o;
  const MatrixX<Scalar>& stats = encoder.forward(b.encoder_input);
  const MatrixX<Scalar> mu = stats.topRows(Z);
  b.raw_log_var = stats.bottomRows(Z);
  b.log_var = b.raw_log_var.cwiseMax(-clamp).cwiseMin(clamp);
  b.sigma = (Scalar(0.5) * b.log_var.array()).exp().matrix();
  b.decoder_input.resize(Z + dobs, batch);
  b.decoder_input.topRows(Z) = mu.array() + b.sigma.array() * noise.array();
  b.decoder_input.bottomRows(dobs) = o;
  const MatrixX<Scalar>& a_hat = decoder.forward(b.decoder_input);
  const double reconstruction = mse_loss<Scalar>(a_hat, a, b.d_a);
  const double kl = gaussian_kl_loss<Scalar>(mu, b.log_var, kl_weight, b.d_mu, b.d_log_var);
  const MatrixX<Scalar>& d_decoder_input = decoder.backward(b.d_a);
  // dz/dmu = 1, dz/dlogvar = eps exp(logvar / 2) / 2; the clamp passes no gradient where active.
  b.d_stats.resize(2 * Z, batch);
  b.d_stats.topRows(Z) = d_decoder_input.topRows(Z) + b.d_mu;
  b.d_stats.bottomRows(Z) =
      (d_decoder_input.topRows(Z).array() * noise.array() * b.sigma.array() * Scalar(0.5) +
       b.d_log_var.array())
          .matrix();
  b.d_stats.bottomRows(Z).array() *= (b.raw_log_var.array().abs() < clamp).template cast<Scalar>();
  encoder.backward(b.d_stats);
  return reconstruction + kl;
}

template double cvae_loss_and_gradients<float>(MlpT<float>&, MlpT<float>&, const MatrixX<float>&,
                                               const MatrixX<float>&, const MatrixX<float>&, double,
                                               CvaeBuffers<float>&);
template double cvae_loss_and_gradients<double>(MlpT<double>&, MlpT<double>&,
                                                const MatrixX<double>&, const MatrixX<double>&,
                                                const MatrixX<double>&, double,
                                                CvaeBuffers<double>&);

}  // namespace handcentric::policy
