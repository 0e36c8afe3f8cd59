#include "handcentric/policy/head.hpp"

#include <string>

#include "handcentric/core/errors.hpp"
#include "handcentric/policy/c8_planar.hpp"
#include "handcentric/policy/losses.hpp"
#include "handcentric/policy/slice_team.hpp"
#include "handcentric/policy/time_embedding.hpp"
#include "image_flow_head.hpp"
#include "network_head.hpp"
#include "normalizer_io.hpp"

namespace handcentric::policy {

std::unique_ptr<Head> make_flow_head(const PolicyConfig& config);
std::unique_ptr<Head> make_ddpm_head(const PolicyConfig& config);
std::unique_ptr<Head> make_cvae_head(const PolicyConfig& config);
std::unique_ptr<Head> make_c8_flow_head(const PolicyConfig& config);
std::unique_ptr<Head> make_c8_planar_head(const PolicyConfig& config);
std::unique_ptr<Head> make_image_flow_head(const PolicyConfig& config);

namespace {
// An image config describes its image and an observation vector with rows for the
// proprioception (at least T_0) besides it.
void check_image_config(const PolicyConfig& config, const std::string& where) {
  if (config.image_size() < 1 || config.proprio_dimension() < 1) {
    throw InvalidArgument(
        where + ": an image policy's image (" + std::to_string(config.image_channels) + " x " +
        std::to_string(config.image_height) + " x " + std::to_string(config.image_width) +
        ") and observation_dimension " + std::to_string(config.observation_dimension) +
        " leave no image or no proprioception: set them from the camera and "
        "the training data");
  }
}
}  // namespace

void Head::set_threads(int threads) {
  if (threads < 1 || threads > SliceTeam::kMaxThreads) {
    throw InvalidArgument("training threads " + std::to_string(threads) + ": use 1 to " +
                          std::to_string(SliceTeam::kMaxThreads));
  }
}

std::unique_ptr<Head> make_head(const PolicyConfig& config) {
  config.validate();
  if (config.action_dimension < 1 || config.observation_dimension < 1) {
    throw InvalidArgument("make_head: action_dimension " + std::to_string(config.action_dimension) +
                          " and observation_dimension " +
                          std::to_string(config.observation_dimension) +
                          " must be set (>= 1) from the training data first");
  }
  if (config.observation == ObservationKind::image) {
    check_image_config(config, "make_head");
    return make_image_flow_head(config);  // validate(): image policies have head flow
  }
  switch (config.head) {
    case HeadKind::flow:
      return make_flow_head(config);
    case HeadKind::ddpm:
      return make_ddpm_head(config);
    case HeadKind::cvae:
      return make_cvae_head(config);
    case HeadKind::c8flow:
      return make_c8_flow_head(config);
    case HeadKind::c8ddpm:
    case HeadKind::c8flow_planar:
    case HeadKind::c8ddpm_avg:
    case HeadKind::c8flow_avg:
      return make_c8_planar_head(config);
  }
  throw InvalidArgument("make_head: unknown head");
}

namespace {
// Weights of an MLP input -> hidden_layers x hidden_width -> output (W and b of every layer).
std::uint64_t mlp_parameter_count(std::uint64_t input, const PolicyConfig& config,
                                  std::uint64_t output) {
  const auto width = static_cast<std::uint64_t>(config.hidden_width);
  std::uint64_t total = 0, fan_in = input;
  for (int l = 0; l < config.hidden_layers; ++l) {
    total += (fan_in + 1) * width;
    fan_in = width;
  }
  return total + (fan_in + 1) * output;
}
}  // namespace

std::uint64_t parameter_count(const PolicyConfig& config) {
  // The same checks as make_head; validate() bounds every size, so nothing below overflows.
  config.validate();
  if (config.action_dimension < 1 || config.observation_dimension < 1) {
    throw InvalidArgument("parameter_count: action_dimension " +
                          std::to_string(config.action_dimension) + " and observation_dimension " +
                          std::to_string(config.observation_dimension) +
                          " must be set (>= 1) from the training data first");
  }
  if (is_c8_planar(config.head)) return parameter_count(c8::inner_config(config));
  const auto actions = static_cast<std::uint64_t>(config.action_dimension);
  const auto observations = static_cast<std::uint64_t>(config.observation_dimension);
  const auto latent = static_cast<std::uint64_t>(config.cvae_latent);
  const auto time = static_cast<std::uint64_t>(time_feature_count(config.time_embedding));
  if (config.head == HeadKind::cvae) {
    return mlp_parameter_count(actions + observations, config, 2 * latent) +
           mlp_parameter_count(latent + observations, config, actions);
  }
  if (config.observation == ObservationKind::image) {
    check_image_config(config, "parameter_count");
    const auto features = static_cast<std::uint64_t>(image_feature_rows(config));
    return mlp_parameter_count(
               actions + time + static_cast<std::uint64_t>(config.proprio_dimension()) + features,
               config, actions) +
           static_cast<std::uint64_t>(config_encoder(config).parameter_count());
  }
  return mlp_parameter_count(actions + time + observations, config, actions);
}

namespace {
std::vector<int> network_widths(const PolicyConfig& config, int observation_rows, int output) {
  std::vector<int> widths{config.action_dimension + time_feature_count(config.time_embedding) +
                          observation_rows};
  for (int l = 0; l < config.hidden_layers; ++l) widths.push_back(config.hidden_width);
  widths.push_back(output);
  return widths;
}
}  // namespace

NetworkHead::NetworkHead(const PolicyConfig& config)
    : NetworkHead(config, config.observation_dimension) {}

NetworkHead::NetworkHead(const PolicyConfig& config, int network_observation_rows)
    : config_(config),
      action_normalizer_(config.action_dimension),
      observation_normalizer_(config.observation_dimension),
      network_(network_widths(config, network_observation_rows, config.action_dimension),
               config.activation),
      adam_(network_.parameter_count(),
            AdamOptions{config.learning_rate, 0.9, 0.999, 1e-8, config.weight_decay}),
      average_(config.ema_decay) {}

void NetworkHead::prepare(const Eigen::MatrixXd& actions, const Eigen::MatrixXd& observations,
                          std::mt19937_64& rng) {
  action_normalizer_ = Normalizer::fit(actions);
  observation_normalizer_ = Normalizer::fit(observations);
  network_.initialize(rng);
}

int NetworkHead::time_rows() const {
  return time_feature_count(config_.time_embedding);
}

void NetworkHead::assemble(const Eigen::MatrixXf& x, const Eigen::VectorXd& t,
                           const Eigen::MatrixXf& o, Eigen::MatrixXf& input) const {
  const Eigen::Index da = x.rows(), dt = time_rows(), batch = x.cols();
  input.resize(da + dt + o.rows(), batch);
  input.topRows(da) = x;
  input.bottomRows(o.rows()) = o;
  Eigen::VectorXf features(dt);
  for (Eigen::Index j = 0; j < batch; ++j) {
    time_features(t[j], config_.time_embedding, features);
    input.block(da, j, dt, 1) = features;
  }
}

void NetworkHead::assemble(const Eigen::MatrixXf& x, const Eigen::MatrixXf& features,
                           std::span<const int> times, const Eigen::MatrixXf& o,
                           Eigen::MatrixXf& input) const {
  const Eigen::Index da = x.rows(), dt = time_rows(), batch = x.cols();
  input.resize(da + dt + o.rows(), batch);
  input.topRows(da) = x;
  input.bottomRows(o.rows()) = o;
  for (Eigen::Index j = 0; j < batch; ++j)
    input.block(da, j, dt, 1) = features.col(times[static_cast<std::size_t>(j)]);
}

double NetworkHead::regress(const Eigen::MatrixXf& output, const Eigen::MatrixXf& target) {
  const double loss = mse_loss<float>(output, target, d_output_);  // eq. (5), averaged
  network_.backward_parameters(d_output_);
  // Clipping folded into Adam's step: the gradient is read once more, not copied and rewritten.
  const float clip = gradient_clip_scale(network_.gradient(), config_.gradient_clip);
  adam_.step(network_.parameters(), network_.gradient(), clip);
  average_.update(network_.parameters());
  return loss;
}

void NetworkHead::finish_training() {
  if (average_.updates() > 0) network_.parameters() = average_.average();
}

void NetworkHead::write(ByteWriter& out) const {
  write_normalizers(out, action_normalizer_, observation_normalizer_);
  out.floats(network_.parameters());
}

void NetworkHead::read(ByteReader& in) {
  read_normalizers(in, config_, action_normalizer_, observation_normalizer_);
  network_.parameters() = in.floats(network_.parameter_count());
}

}  // namespace handcentric::policy
