// The image policy's flow head (image_flow_head.hpp): eq. (5) with the observation's image
// encoded by a ConvEncoder trained end to end.
#include "image_flow_head.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>

#include "handcentric/core/errors.hpp"

namespace handcentric::policy {

ImageShape config_image_shape(const PolicyConfig& config) {
  return ImageShape{config.image_channels, config.image_height, config.image_width};
}

std::vector<ConvLayerSpec> config_encoder_layers(const PolicyConfig& config) {
  std::vector<ConvLayerSpec> layers;
  for (const EncoderLayerSetting& layer : parse_encoder(config.encoder))
    layers.push_back(ConvLayerSpec{layer.channels, 3, layer.stride, 1});
  return layers;
}

ConvEncoder config_encoder(const PolicyConfig& config) {
  return ConvEncoder(config_image_shape(config), config_encoder_layers(config));
}

int image_feature_rows(const PolicyConfig& config) {
  const ConvEncoder encoder = config_encoder(config);
  return static_cast<int>(config.image_features == ImageFeatures::spatial_softmax
                              ? 2 * encoder.output_shape().channels
                              : encoder.output_size());
}

namespace {
int network_observation_rows(const PolicyConfig& config) {
  return config.proprio_dimension() + image_feature_rows(config);
}
}  // namespace

ImageFlowHead::ImageFlowHead(const PolicyConfig& config)
    : FlowHead(config, network_observation_rows(config)),
      proprio_rows_(config.proprio_dimension()),
      encoder_(config_encoder(config)),
      keypoints_(config.image_features == ImageFeatures::spatial_softmax),
      spatial_softmax_(encoder_.output_shape()),
      encoder_adam_(encoder_.parameter_count(),
                    AdamOptions{config.learning_rate, 0.9, 0.999, 1e-8, config.weight_decay}),
      encoder_average_(config.ema_decay) {}

void ImageFlowHead::prepare(const Eigen::MatrixXd& actions, const Eigen::MatrixXd& observations,
                            std::mt19937_64& rng) {
  FlowHead::prepare(actions, observations, rng);
  encoder_.initialize(rng);
}

Eigen::MatrixXf ImageFlowHead::network_observation(ConvEncoder& encoder, SpatialSoftmax& softmax,
                                                   const Eigen::MatrixXf& o) const {
  return with_features(softmax, o.topRows(proprio_rows_),
                       encoder.forward(o.bottomRows(o.rows() - proprio_rows_)));
}

Eigen::MatrixXf ImageFlowHead::with_features(SpatialSoftmax& softmax,
                                             const Eigen::Ref<const Eigen::MatrixXf>& proprio,
                                             const Eigen::MatrixXf& maps) const {
  const Eigen::MatrixXf& features = keypoints_ ? softmax.forward(maps) : maps;
  Eigen::MatrixXf out(proprio_rows_ + features.rows(), maps.cols());
  out.topRows(proprio_rows_) = proprio;
  out.bottomRows(features.rows()) = features;
  return out;
}

double ImageFlowHead::train_step(const Eigen::MatrixXf& actions,
                                 const Eigen::MatrixXf& observations, std::mt19937_64& rng) {
  action_normalizer_.normalize(actions, a_);
  observation_normalizer_.normalize(observations, o_);
  const Eigen::Index pixels = o_.rows() - proprio_rows_;
  return train_in_slices(
      rng,
      [&](ConvEncoder& encoder, Eigen::Index first, Eigen::Index count) -> const Eigen::MatrixXf& {
        return encoder.forward(o_.bottomRows(pixels).middleCols(first, count));
      });
}

double ImageFlowHead::train_step_on(const Minibatch& batch, std::mt19937_64& rng) {
  action_normalizer_.normalize(batch.set_actions, batch.columns, a_);
  // The proprioception rows normalized here, the images by the encoder's first layer as it
  // reads them from the set (the same two roundings per value as normalize()).
  const Eigen::VectorXf& mean = observation_normalizer_.mean_float();
  const Eigen::VectorXf& inv_scale = observation_normalizer_.inv_scale_float();
  const Eigen::MatrixXf& set = batch.set_observations;
  if (set.rows() != observation_normalizer_.dimension()) {
    throw InvalidArgument("ImageFlowHead: a training set of " + std::to_string(set.rows()) +
                          " observation rows, expected " +
                          std::to_string(observation_normalizer_.dimension()));
  }
  o_.resize(proprio_rows_, static_cast<Eigen::Index>(batch.columns.size()));
  for (std::size_t j = 0; j < batch.columns.size(); ++j) {
    const Eigen::Index column = batch.columns[j];
    if (column < 0 || column >= set.cols()) {
      throw InvalidArgument("ImageFlowHead: column " + std::to_string(column) +
                            " picked from a set of " + std::to_string(set.cols()) + " columns");
    }
    o_.col(static_cast<Eigen::Index>(j)).array() =
        (set.col(column).head(proprio_rows_).array() - mean.head(proprio_rows_).array()) *
        inv_scale.head(proprio_rows_).array();
  }
  const std::size_t pixels = static_cast<std::size_t>(set.rows() - proprio_rows_);
  const std::span<const float> pixel_mean(mean.data() + proprio_rows_, pixels);
  const std::span<const float> pixel_inv_scale(inv_scale.data() + proprio_rows_, pixels);
  return train_in_slices(
      rng,
      [&](ConvEncoder& encoder, Eigen::Index first, Eigen::Index count) -> const Eigen::MatrixXf& {
        const PickedImages images{
            set, proprio_rows_,
            batch.columns.subspan(static_cast<std::size_t>(first), static_cast<std::size_t>(count)),
            pixel_mean, pixel_inv_scale};
        return encoder.forward(images);
      });
}

void ImageFlowHead::set_train_slice(int samples) {
  if (samples < 1) {
    throw InvalidArgument("ImageFlowHead: a training slice of " + std::to_string(samples) +
                          " samples; use 1 or more");
  }
  train_slice_ = samples;
}

void ImageFlowHead::set_threads(int threads) {
  Head::set_threads(threads);  // checks the range
  threads_ = threads;
}

template <typename Encode>
double ImageFlowHead::train_in_slices(std::mt19937_64& rng, const Encode& encode) {
  const Eigen::Index batch = a_.cols();
  if (batch == 0) throw InvalidArgument("ImageFlowHead: a training step on no samples");
  draw_flow_sample(rng);  // for the whole batch: the same draws whatever the slices
  // Eq. (5)'s loss is the mean over the whole batch's entries, so each slice's output gradient
  // is scaled by 2 / (the batch's entries), as mse_loss scales it.
  const auto entries = static_cast<double>(target_.size());
  const auto d_scale = static_cast<float>(2.0 / entries);

  // No more lanes than slices; lanes beyond the first compute on copies of the weights.
  const Eigen::Index slices = (batch + train_slice_ - 1) / train_slice_;
  const int lanes = static_cast<int>(std::min<Eigen::Index>(threads_, slices));
  if (!team_ || team_->threads() != lanes) team_ = std::make_unique<SliceTeam>(lanes);
  if (lane_buffers_.size() < static_cast<std::size_t>(lanes)) lane_buffers_.resize(lanes);
  while (lane_networks_.size() + 1 < static_cast<std::size_t>(lanes))
    lane_networks_.push_back(LaneNetworks{network_, encoder_, spatial_softmax_});
  for (int lane = 1; lane < lanes; ++lane) {
    LaneNetworks& copy = lane_networks_[static_cast<std::size_t>(lane - 1)];
    copy.network.parameters() = network_.parameters();
    copy.encoder.parameters() = encoder_.parameters();
  }
  const auto networks = [&](int lane) {
    if (lane == 0) return std::tie(network_, encoder_, spatial_softmax_);
    LaneNetworks& copy = lane_networks_[static_cast<std::size_t>(lane - 1)];
    return std::tie(copy.network, copy.encoder, copy.softmax);
  };

  const auto compute = [&](int lane, long first, long count) {
    auto [network, encoder, softmax] = networks(lane);
    LaneBuffers& buffers = lane_buffers_[static_cast<std::size_t>(lane)];
    const Eigen::MatrixXf& maps = encode(encoder, first, count);
    buffers.network_o =
        with_features(softmax, o_.topRows(proprio_rows_).middleCols(first, count), maps);
    assemble(x_.middleCols(first, count), t_.segment(first, count), buffers.network_o,
             buffers.input);
    buffers.d_output = network.forward(buffers.input) - target_.middleCols(first, count);
    buffers.squared_error = static_cast<double>(buffers.d_output.squaredNorm());
    buffers.d_output *= d_scale;
    // End to end: the MLP's input gradient, its feature rows (the last ones), into the encoder.
    const Eigen::MatrixXf& d_input = network.backward(buffers.d_output);
    const Eigen::Index features = buffers.network_o.rows() - proprio_rows_;
    if (keypoints_) {
      encoder.backward_parameters(softmax.backward(d_input.bottomRows(features)));
    } else {
      encoder.backward_parameters(d_input.bottomRows(features));
    }
  };
  double squared_error = 0.0;
  const auto add = [&](int lane, long first) {  // in slice order (SliceTeam)
    auto [network, encoder, softmax] = networks(lane);
    if (first == 0) {
      network_gradient_ = network.gradient();
      encoder_gradient_ = encoder.gradient();
    } else {
      network_gradient_ += network.gradient();
      encoder_gradient_ += encoder.gradient();
    }
    squared_error += lane_buffers_[static_cast<std::size_t>(lane)].squared_error;
  };
  team_->run(batch, train_slice_, compute, add);

  // One clip over both gradients: the norm of their concatenation.
  double scale = 1.0;
  if (config_.gradient_clip > 0.0) {
    const double norm = std::sqrt(static_cast<double>(network_gradient_.squaredNorm()) +
                                  static_cast<double>(encoder_gradient_.squaredNorm()));
    if (norm > config_.gradient_clip) scale = config_.gradient_clip / norm;
  }
  adam_.step(network_.parameters(), network_gradient_, static_cast<float>(scale));
  encoder_adam_.set_learning_rate(adam_.learning_rate());
  encoder_adam_.step(encoder_.parameters(), encoder_gradient_, static_cast<float>(scale));
  average_.update(network_.parameters());
  encoder_average_.update(encoder_.parameters());
  return squared_error / entries;
}

Eigen::MatrixXf ImageFlowHead::sample(const Eigen::MatrixXf& observations,
                                      std::mt19937_64& rng) const {
  Eigen::MatrixXf o = observations;
  observation_normalizer_.normalize(o);
  // forward() keeps its activations, so a const sampler runs a copy: one policy may act from
  // several threads. The copy is the weights alone (a few thousand), not the last training
  // batch's activations; the spatial softmax has no weights.
  ConvEncoder encoder = encoder_;
  SpatialSoftmax softmax(spatial_softmax_.map_shape());
  const Eigen::MatrixXf network_o = network_observation(encoder, softmax, o);
  return sample_normalized(network_o, rng);
}

void ImageFlowHead::finish_training() {
  FlowHead::finish_training();
  if (encoder_average_.updates() > 0) encoder_.parameters() = encoder_average_.average();
}

void ImageFlowHead::write(ByteWriter& out) const {
  FlowHead::write(out);
  encoder_.write(out);
}

void ImageFlowHead::read(ByteReader& in) {
  FlowHead::read(in);
  ConvEncoder stored = ConvEncoder::read(in);
  const ConvEncoder expected = config_encoder(config_);
  bool same = stored.input_shape() == expected.input_shape() &&
              stored.layers().size() == expected.layers().size();
  for (std::size_t l = 0; same && l < stored.layers().size(); ++l) {
    const Conv2d &a = stored.layers()[l], &b = expected.layers()[l];
    same = a.out_channels() == b.out_channels() && a.kernel() == b.kernel() &&
           a.stride() == b.stride() && a.padding() == b.padding();
  }
  if (!same) {
    in.fail("the image encoder stored is not the one its config describes (encoder " +
            config_.encoder + " on " + std::to_string(config_.image_channels) + " x " +
            std::to_string(config_.image_height) + " x " + std::to_string(config_.image_width) +
            " images)");
  }
  encoder_ = std::move(stored);
}

const ConvEncoder* image_encoder(const Head& head) {
  const auto* image = dynamic_cast<const ImageFlowHead*>(&head);
  return image == nullptr ? nullptr : &image->encoder();
}

std::unique_ptr<Head> make_image_flow_head(const PolicyConfig& config) {
  return std::make_unique<ImageFlowHead>(config);
}

}  // namespace handcentric::policy
