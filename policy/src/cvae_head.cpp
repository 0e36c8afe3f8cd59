// Conditional VAE (Sohn et al. 2015), for the App. B ablation, in normalized coordinates. The
// objective and its gradients: cvae_loss.hpp. Sampling: z ~ N(0, I), a = D([z; o]).
#include <cmath>

#include "handcentric/core/errors.hpp"
#include "handcentric/policy/adam.hpp"
#include "handcentric/policy/gaussian.hpp"
#include "handcentric/policy/head.hpp"
#include "handcentric/policy/cvae_loss.hpp"
#include "handcentric/policy/mlp.hpp"
#include "handcentric/policy/normalizer.hpp"
#include "handcentric/policy/weight_average.hpp"
#include "normalizer_io.hpp"

namespace handcentric::policy {
namespace {

std::vector<int> widths(const PolicyConfig& config, int input, int output) {
  std::vector<int> w{input};
  for (int l = 0; l < config.hidden_layers; ++l) w.push_back(config.hidden_width);
  w.push_back(output);
  return w;
}

class CvaeHead final : public Head {
 public:
  explicit CvaeHead(const PolicyConfig& config)
      : config_(config),
        action_normalizer_(config.action_dimension),
        observation_normalizer_(config.observation_dimension),
        encoder_(widths(config, config.action_dimension + config.observation_dimension,
                        2 * config.cvae_latent),
                 config.activation),
        decoder_(widths(config, config.cvae_latent + config.observation_dimension,
                        config.action_dimension),
                 config.activation),
        encoder_adam_(encoder_.parameter_count(), options(config)),
        decoder_adam_(decoder_.parameter_count(), options(config)),
        decoder_average_(config.ema_decay) {}

  HeadKind kind() const override { return HeadKind::cvae; }

  void prepare(const Eigen::MatrixXd& actions, const Eigen::MatrixXd& observations,
               std::mt19937_64& rng) override {
    action_normalizer_ = Normalizer::fit(actions);
    observation_normalizer_ = Normalizer::fit(observations);
    encoder_.initialize(rng);
    decoder_.initialize(rng);
  }

  double train_step(const Eigen::MatrixXf& actions, const Eigen::MatrixXf& observations,
                    std::mt19937_64& rng) override {
    action_normalizer_.normalize(actions, a_);
    observation_normalizer_.normalize(observations, o_);
    noise_.resize(config_.cvae_latent, actions.cols());
    fill_standard_normal(rng, noise_);
    const double loss = cvae_loss_and_gradients<float>(encoder_, decoder_, a_, o_, noise_,
                                                       config_.cvae_kl_weight, buffers_);
    step(decoder_, decoder_adam_);
    step(encoder_, encoder_adam_);
    decoder_average_.update(decoder_.parameters());
    return loss;
  }

  // Sampling uses the decoder only, so only the decoder's weights are averaged.
  void finish_training() override {
    if (decoder_average_.updates() > 0) decoder_.parameters() = decoder_average_.average();
  }

  void set_learning_rate(double learning_rate) override {
    encoder_adam_.set_learning_rate(learning_rate);
    decoder_adam_.set_learning_rate(learning_rate);
  }

  Eigen::MatrixXf sample(const Eigen::MatrixXf& observations, std::mt19937_64& rng) const override {
    const Eigen::Index batch = observations.cols(), dobs = observations.rows(),
                       Z = config_.cvae_latent;
    Eigen::MatrixXf input(Z + dobs, batch), output, scratch[2];
    fill_standard_normal(rng, input.topRows(Z));
    input.bottomRows(dobs) = observations;
    observation_normalizer_.normalize(input.bottomRows(dobs));
    decoder_.infer(input, output, scratch);
    action_normalizer_.denormalize(output);
    return output;
  }

  void write(ByteWriter& out) const override {
    write_normalizers(out, action_normalizer_, observation_normalizer_);
    out.floats(encoder_.parameters());
    out.floats(decoder_.parameters());
  }

  void read(ByteReader& in) override {
    read_normalizers(in, config_, action_normalizer_, observation_normalizer_);
    encoder_.parameters() = in.floats(encoder_.parameter_count());
    decoder_.parameters() = in.floats(decoder_.parameter_count());
  }

 private:
  static AdamOptions options(const PolicyConfig& config) {
    return AdamOptions{config.learning_rate, 0.9, 0.999, 1e-8, config.weight_decay};
  }
  void step(Mlp& network, Adam& adam) {
    adam.step(network.parameters(), network.gradient(),
              gradient_clip_scale(network.gradient(), config_.gradient_clip));
  }

  PolicyConfig config_;
  Normalizer action_normalizer_, observation_normalizer_;
  Mlp encoder_, decoder_;
  Adam encoder_adam_, decoder_adam_;
  WeightAverage decoder_average_;
  Eigen::MatrixXf a_, o_, noise_;
  CvaeBuffers<float> buffers_;
};

}  // namespace

std::unique_ptr<Head> make_cvae_head(const PolicyConfig& config) {
  return std::make_unique<CvaeHead>(config);
}

}  // namespace handcentric::policy
