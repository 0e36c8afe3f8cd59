// Rectified flow matching, Sec. 2.3:
//   training  x_t = t a + (1 - t) eps,  target u = a - eps,
//             L = |f_theta(x_t, t, o) - u|^2                                           eq. (5)
//   sampling  x_0 = eps,  x_{n+1} = x_n + (1/N) f_theta(x_n, n/N, o),  n = 0..N-1 (Euler)
// in normalized coordinates (normalizer.hpp), eps ~ N(0, I) there; dimensions that are constant
// in the training data (normalizer.hpp, active = 0) get no noise and no velocity.
#include "flow_head.hpp"

#include "handcentric/core/sampling.hpp"
#include "handcentric/policy/gaussian.hpp"
#include "handcentric/policy/time_embedding.hpp"

namespace handcentric::policy {

double FlowHead::train_step(const Eigen::MatrixXf& actions, const Eigen::MatrixXf& observations,
                            std::mt19937_64& rng) {
  action_normalizer_.normalize(actions, a_);
  observation_normalizer_.normalize(observations, o_);
  return train_normalized(rng);
}

double FlowHead::train_normalized(std::mt19937_64& rng) {
  draw_flow_sample(rng);
  assemble(x_, t_, o_, input_);
  return regress(network_.forward(input_), target_);
}

void FlowHead::draw_flow_sample(std::mt19937_64& rng) {
  const Eigen::Index batch = a_.cols();
  noise_.resize(a_.rows(), batch);
  fill_standard_normal(rng, noise_);
  noise_.array().colwise() *= action_normalizer_.active_float().array();  // constant dims: no noise
  t_.resize(batch);
  for (Eigen::Index j = 0; j < batch; ++j) t_[j] = uniform01(rng);
  x_.resize(a_.rows(), batch);
  for (Eigen::Index j = 0; j < batch; ++j) {
    const float t = static_cast<float>(t_[j]);
    x_.col(j) = t * a_.col(j) + (1.0f - t) * noise_.col(j);  // eq. (5): a(t) = t a + (1 - t) eps
  }
  target_ = a_ - noise_;  // d/dt a(t) = a - eps
}

Eigen::MatrixXf FlowHead::normalized_velocity(const Eigen::MatrixXf& x, double t,
                                              const Eigen::MatrixXf& o) const {
  Eigen::MatrixXf input, output, scratch[2];
  assemble(x, Eigen::VectorXd::Constant(x.cols(), t), o, input);
  network_.infer(input, output, scratch);
  return output;
}

Eigen::MatrixXf FlowHead::initial_noise(Eigen::Index batch, std::mt19937_64& rng) const {
  Eigen::MatrixXf x(config_.action_dimension, batch);
  fill_standard_normal(rng, x);
  x.array().colwise() *=
      action_normalizer_.active_float().array() * static_cast<float>(config_.noise_scale);
  return x;
}

void FlowHead::euler_step(Eigen::MatrixXf& x, const Eigen::MatrixXf& o, int n) const {
  const int steps = config_.euler_steps;
  Eigen::MatrixXf velocity = normalized_velocity(x, static_cast<double>(n) / steps, o);
  velocity.array().colwise() *= action_normalizer_.active_float().array();
  x += velocity * (1.0f / static_cast<float>(steps));
}

Eigen::MatrixXf FlowHead::sample(const Eigen::MatrixXf& observations, std::mt19937_64& rng) const {
  Eigen::MatrixXf o = observations;
  observation_normalizer_.normalize(o);
  return sample_normalized(o, rng);
}

Eigen::MatrixXf FlowHead::sample_normalized(const Eigen::MatrixXf& o, std::mt19937_64& rng) const {
  const Eigen::Index batch = o.cols();
  Eigen::MatrixXf x = initial_noise(batch, rng);
  const Eigen::VectorXf& active = action_normalizer_.active_float();
  Eigen::MatrixXf input, velocity, scratch[2];
  const Eigen::VectorXd t0 = Eigen::VectorXd::Zero(batch);
  assemble(x, t0, o, input);  // sizes the input once; per step only x and the time rows change
  const Eigen::Index da = x.rows(), dt = time_rows();
  Eigen::VectorXf features(dt);
  const int steps = config_.euler_steps;
  for (int n = 0; n < steps; ++n) {
    const double t = static_cast<double>(n) / steps;
    time_features(t, config_.time_embedding, features);
    input.topRows(da) = x;
    input.middleRows(da, dt).colwise() = features;
    network_.infer(input, velocity, scratch);
    velocity.array().colwise() *= active.array();
    x += velocity * (1.0f / static_cast<float>(steps));  // Euler step of length 1/N
  }
  action_normalizer_.denormalize(x);
  return x;
}

std::unique_ptr<Head> make_flow_head(const PolicyConfig& config) {
  return std::make_unique<FlowHead>(config);
}

}  // namespace handcentric::policy
