// DDPM (Ho et al. 2020) for the App. B ablation; DDIM sampling (Song et al. 2021, eta = 0) in
// config.ddim_steps steps. In normalized coordinates, like the flow head. The network predicts
// the clean chunk (config.ddpm_prediction = sample, the default) or the noise (epsilon).
//
//   schedule  cosine (Nichol & Dhariwal 2021): abar(s) = cos^2(((s / T) + 0.008) / 1.008 * pi / 2)
//             normalized by abar(0), beta_k = min(1 - abar_k / abar_{k-1}, 0.999),
//             abar_k = prod(1 - beta)
//   training  k uniform in 0..T-1, x = sqrt(abar_k) a + sqrt(1 - abar_k) eps, target a (sample)
//             or eps (epsilon), network input [x, time features of (k + 1) / T, o]
//   sampling  tau_i = T - 1 - i * (T / S), i = 0..S-1;
//             sample:  x0_hat = the network's output,
//                      eps_hat = (x - sqrt(abar) x0_hat) / sqrt(1 - abar);
//             epsilon: x0_hat = (x - sqrt(1 - abar) eps_hat) / sqrt(abar);
//             x0_hat clipped to the range of the normalized training actions (at least +-1), as
//             Diffusion Policy clips to its data range;
//             x <- sqrt(abar_prev) x0_hat + sqrt(1 - abar_prev) eps_hat.
//             With epsilon, the first step (abar_{T-1} ~ 2e-7) multiplies any error in eps_hat
//             by ~2000: without the clip the later steps would start far outside the training
//             distribution, and even with it the chunk misses the 0.1 cm clearance (0.00
//             success where sample prediction reaches 0.87; docs/EXPERIMENTS.md). With sample,
//             no step divides by sqrt(abar): eps_hat divides by sqrt(1 - abar), at least 0.025
//             (k = 0; 0.17 at the smallest k of 10 DDIM steps), and the last step returns
//             x0_hat itself (abar_prev = 1).
#include <algorithm>
#include <cmath>
#include <string>
#include <numbers>
#include <vector>

#include "handcentric/policy/gaussian.hpp"
#include "handcentric/policy/time_embedding.hpp"
#include "ddpm_head.hpp"

namespace handcentric::policy {
namespace {

std::vector<double> cosine_alpha_bar(int T) {
  const auto f = [T](double s) {
    const double c = std::cos((s / T + 0.008) / 1.008 * std::numbers::pi / 2.0);
    return c * c;
  };
  std::vector<double> alpha_bar(T);
  double product = 1.0;
  for (int k = 0; k < T; ++k) {
    const double beta = std::min(1.0 - f(k + 1) / f(k), 0.999);
    product *= 1.0 - beta;
    alpha_bar[k] = product;
  }
  return alpha_bar;
}

}  // namespace

DdpmHead::DdpmHead(const PolicyConfig& config)
    : NetworkHead(config),
      alpha_bar_(cosine_alpha_bar(config.ddpm_train_steps)),
      time_features_(time_rows(), config.ddpm_train_steps),
      initial_noise_(static_cast<float>(config.noise_scale)) {
  const int T = config.ddpm_train_steps;
  for (int k = 0; k < T; ++k)
    time_features(static_cast<double>(k + 1) / T, config.time_embedding, time_features_.col(k));
}

void DdpmHead::prepare(const Eigen::MatrixXd& actions, const Eigen::MatrixXd& observations,
                       std::mt19937_64& rng) {
  NetworkHead::prepare(actions, observations, rng);
  Eigen::MatrixXf normalized = actions.cast<float>();
  action_normalizer_.normalize(normalized);
  clip_ = std::max(1.0f, normalized.cwiseAbs().maxCoeff());
}

void DdpmHead::write(ByteWriter& out) const {
  NetworkHead::write(out);
  out.f64(clip_);
}

void DdpmHead::read(ByteReader& in) {
  NetworkHead::read(in);
  const double clip = in.f64();
  if (!(clip >= 1.0 && clip < 1e6)) in.fail("a DDPM clip range of " + std::to_string(clip));
  clip_ = static_cast<float>(clip);
}

double DdpmHead::train_step(const Eigen::MatrixXf& actions, const Eigen::MatrixXf& observations,
                            std::mt19937_64& rng) {
  action_normalizer_.normalize(actions, a_);
  observation_normalizer_.normalize(observations, o_);
  const Eigen::Index batch = a_.cols();
  const int T = config_.ddpm_train_steps;
  noise_.resize(a_.rows(), batch);
  fill_standard_normal(rng, noise_);
  noise_.array().colwise() *= action_normalizer_.active_float().array();  // constant dims: no noise
  steps_.resize(static_cast<std::size_t>(batch));
  x_.resize(a_.rows(), batch);
  for (Eigen::Index j = 0; j < batch; ++j) {
    const int k = static_cast<int>(rng() % static_cast<std::uint64_t>(T));
    steps_[static_cast<std::size_t>(j)] = k;
    x_.col(j) = static_cast<float>(std::sqrt(alpha_bar_[k])) * a_.col(j) +
                static_cast<float>(std::sqrt(1.0 - alpha_bar_[k])) * noise_.col(j);
  }
  assemble(x_, time_features_, steps_, o_, input_);
  return regress(network_.forward(input_),
                 config_.ddpm_prediction == DdpmPrediction::sample ? a_ : noise_);
}

Eigen::MatrixXf DdpmHead::initial_noise(Eigen::Index batch, std::mt19937_64& rng) const {
  Eigen::MatrixXf x(config_.action_dimension, batch);
  fill_standard_normal(rng, x);
  x.array().colwise() *= action_normalizer_.active_float().array() * initial_noise_;
  return x;
}

void DdpmHead::ddim_step(Eigen::MatrixXf& x, const Eigen::MatrixXf& o, int i) const {
  const Eigen::Index batch = x.cols();
  const int T = config_.ddpm_train_steps, S = config_.ddim_steps;
  const int k = T - 1 - i * (T / S);
  const int k_prev = i + 1 < S ? T - 1 - (i + 1) * (T / S) : -1;
  const double abar = alpha_bar_[k], abar_prev = k_prev >= 0 ? alpha_bar_[k_prev] : 1.0;
  const float signal = static_cast<float>(std::sqrt(abar));
  const float noise = static_cast<float>(std::sqrt(1.0 - abar));
  Eigen::MatrixXf input, output, x0, eps_hat, scratch[2];
  assemble(x, time_features_, std::vector<int>(static_cast<std::size_t>(batch), k), o, input);
  network_.infer(input, output, scratch);
  output.array().colwise() *= action_normalizer_.active_float().array();
  if (config_.ddpm_prediction == DdpmPrediction::sample) {
    x0 = output.cwiseMax(-clip_).cwiseMin(clip_);
    eps_hat = (x - signal * x0) / noise;
  } else {
    eps_hat = output;
    x0 = ((x - noise * eps_hat) / signal).cwiseMax(-clip_).cwiseMin(clip_);
  }
  x = static_cast<float>(std::sqrt(abar_prev)) * x0 +
      static_cast<float>(std::sqrt(1.0 - abar_prev)) * eps_hat;
}

Eigen::MatrixXf DdpmHead::sample(const Eigen::MatrixXf& observations, std::mt19937_64& rng) const {
  Eigen::MatrixXf o = observations;
  observation_normalizer_.normalize(o);
  Eigen::MatrixXf x = initial_noise(o.cols(), rng);
  for (int i = 0; i < config_.ddim_steps; ++i) ddim_step(x, o, i);
  action_normalizer_.denormalize(x);
  return x;
}

// DDIM starts at config.noise_scale times the prior's noise, as the flow heads' Euler
// integration does: 0 (the default) samples the most likely chunk (eq. 6), which the 0.1 cm
// clearance needs (docs/EXPERIMENTS.md).
std::unique_ptr<Head> make_ddpm_head(const PolicyConfig& config) {
  return std::make_unique<DdpmHead>(config);
}

}  // namespace handcentric::policy
