#pragma once
// Private: the rectified-flow head of an image policy (PolicyConfig::observation = image). The
// observation columns are [proprioception; image] (image_source.hpp); the image goes through a
// ConvEncoder whose features take its place in the MLP's input:
//
//   MLP input = [x (actions), time features, proprioception, encoder(image) features]
//
// The features are the encoder's last map flattened, or with image_features = spatial_softmax
// one soft-argmax point (x, y) per channel of it (spatial_softmax.hpp).
//
// Trained end to end: eq. (5)'s loss is backpropagated through the MLP into the features and on
// through the encoder (ConvEncoder::backward_parameters), one slice of kImageTrainSlice samples
// at a time (conv_encoder.hpp: the slice's activations stay in cache), the gradients summed
// over the slices; the MLP's and the encoder's gradients are clipped together by their joint
// norm, and each set of weights takes the same Adam step (Adam is elementwise, so two Adams are
// one Adam over both). Both normalizers see the whole observation: each pixel is shifted and
// scaled by its training mean and spread, a constant map that keeps an invariant image invariant
// (normalizer.hpp).
#include <memory>
#include <vector>

#include "flow_head.hpp"
#include "handcentric/policy/conv_encoder.hpp"
#include "handcentric/policy/slice_team.hpp"
#include "handcentric/policy/spatial_softmax.hpp"

namespace handcentric::policy {

/// config's image (image_channels, image_height, image_width).
ImageShape config_image_shape(const PolicyConfig& config);
/// config.encoder as layers: each a 3 x 3 convolution, stride 2 (or 1), padding 1.
std::vector<ConvLayerSpec> config_encoder_layers(const PolicyConfig& config);
/// The encoder an image config describes (weights zero). Throws InvalidArgument for a bad one.
ConvEncoder config_encoder(const PolicyConfig& config);
/// The features the MLP gets in the pixels' place: the encoder's output, or 2 per channel of
/// its last map with spatial_softmax.
int image_feature_rows(const PolicyConfig& config);

class ImageFlowHead final : public FlowHead {
 public:
  explicit ImageFlowHead(const PolicyConfig& config);
  void prepare(const Eigen::MatrixXd& actions, const Eigen::MatrixXd& observations,
               std::mt19937_64& rng) override;
  double train_step(const Eigen::MatrixXf& actions, const Eigen::MatrixXf& observations,
                    std::mt19937_64& rng) override;
  /// train_step on the drawn columns read straight from the training set: the proprioception
  /// normalized here, the images by the encoder's first layer as it pads them (PickedImages).
  /// The same bits, without the trainer's copy of the batch nor a normalized one (tens of MB of
  /// images a step each).
  double train_step_on(const Minibatch& batch, std::mt19937_64& rng) override;
  bool reads_the_set() const override { return true; }
  Eigen::MatrixXf sample(const Eigen::MatrixXf& observations, std::mt19937_64& rng) const override;
  void finish_training() override;
  /// NetworkHead's record, then the encoder's (ConvEncoder::write).
  void write(ByteWriter& out) const override;
  /// Also refuses an encoder whose architecture is not the config's.
  void read(ByteReader& in) override;

  const ConvEncoder& encoder() const { return encoder_; }
  /// The last training step's gradients (the MLP's, the encoder's), summed over its slices,
  /// before clipping.
  const Eigen::VectorXf& network_gradient() const { return network_gradient_; }
  const Eigen::VectorXf& encoder_gradient() const { return encoder_gradient_; }
  /// Samples per slice of a training step (kImageTrainSlice unless set): the tests compare
  /// slicings. Throws InvalidArgument for less than 1.
  void set_train_slice(int samples);
  void set_threads(int threads) override;

 private:
  /// [proprioception; features] of normalized observations o, with `encoder` (and `softmax`
  /// for spatial_softmax features) run forward.
  Eigen::MatrixXf network_observation(ConvEncoder& encoder, SpatialSoftmax& softmax,
                                      const Eigen::MatrixXf& o) const;
  /// [proprio; features] from the normalized proprioception rows and the encoder's output maps.
  Eigen::MatrixXf with_features(SpatialSoftmax& softmax,
                                const Eigen::Ref<const Eigen::MatrixXf>& proprio,
                                const Eigen::MatrixXf& maps) const;
  /// The step once a_ holds the batch's normalized actions and o_'s first rows its normalized
  /// proprioception: eq. (5)'s sample drawn for the whole batch, then forward and backward
  /// through the MLP and the encoder one slice of train_slice_ samples at a time, on threads_
  /// lanes (SliceTeam), the gradients summed in slice order, one clip and one Adam step.
  /// encode(encoder, first, count) runs `encoder` (a lane's) forward on those samples' images
  /// and returns its maps.
  template <typename Encode>
  double train_in_slices(std::mt19937_64& rng, const Encode& encode);

  /// What a training lane beyond the first computes with: its own MLP and encoder (the head's
  /// weights, copied in at each step) for their activations and gradients.
  struct LaneNetworks {
    Mlp network;
    ConvEncoder encoder;
    SpatialSoftmax softmax;
  };
  /// A lane's slice buffers (the first lane's included).
  struct LaneBuffers {
    Eigen::MatrixXf network_o, input, d_output;
    double squared_error = 0.0;
  };

  int proprio_rows_ = 0;
  ConvEncoder encoder_;
  bool keypoints_ = false;  ///< image_features = spatial_softmax
  SpatialSoftmax spatial_softmax_;
  Adam encoder_adam_;
  WeightAverage encoder_average_;
  Eigen::VectorXf network_gradient_, encoder_gradient_;  ///< summed over a step's slices
  int train_slice_ = kImageTrainSlice;
  int threads_ = 1;
  std::unique_ptr<SliceTeam> team_;          ///< made at the first step, remade when resized
  std::vector<LaneNetworks> lane_networks_;  ///< lanes 1, 2, ... (lane 0 is the head's own)
  std::vector<LaneBuffers> lane_buffers_;    ///< lanes 0, 1, ...
};

}  // namespace handcentric::policy
