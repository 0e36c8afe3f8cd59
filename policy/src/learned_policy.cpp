#include "handcentric/policy/learned_policy.hpp"

#include <random>

#include "handcentric/core/errors.hpp"
#include "handcentric/policy/binary_io.hpp"
#include "handcentric/policy/layer_watch.hpp"

namespace handcentric::policy {

LearnedPolicy::LearnedPolicy(PolicyConfig config,
                             std::shared_ptr<const Representation> representation,
                             std::shared_ptr<const Head> head,
                             std::shared_ptr<const ImageSource> camera)
    : config_(std::move(config)),
      representation_(std::move(representation)),
      head_(std::move(head)),
      camera_(config_.observation == ObservationKind::image ? std::move(camera) : nullptr) {
  if (!representation_ || !head_)
    throw InvalidArgument("LearnedPolicy: null representation or head");
  if (representation_->name() != config_.representation || head_->kind() != config_.head) {
    throw InvalidArgument("LearnedPolicy: config says " + to_string(config_.head) + "/" +
                          config_.representation + " but got " + to_string(head_->kind()) + "/" +
                          representation_->name());
  }
  if (camera_) {
    const ImageShape shape = camera_->shape();
    if (shape.channels != config_.image_channels || shape.height != config_.image_height ||
        shape.width != config_.image_width) {
      throw InvalidArgument(
          "LearnedPolicy: " + camera_->name() + " renders " + std::to_string(shape.channels) +
          " x " + std::to_string(shape.height) + " x " + std::to_string(shape.width) +
          " images but " + name() + " was trained on " + std::to_string(config_.image_channels) +
          " x " + std::to_string(config_.image_height) + " x " +
          std::to_string(config_.image_width) + ": give it a camera of its training shape");
    }
  }
}

LearnedPolicy with_head_kind(const LearnedPolicy& trained, HeadKind kind) {
  const HeadKind from = trained.config().head;
  if (trained_as(kind) != trained_as(from)) {
    throw InvalidArgument("a " + to_string(from) + " model cannot be given head " +
                          to_string(kind) + ": it trains other weights (train --head " +
                          to_string(kind) + " instead)");
  }
  PolicyConfig config = trained.config();
  config.head = kind;
  std::shared_ptr<Head> head = make_head(config);
  // The head's own serialization carries every trained number (the model file's payload).
  ByteWriter weights;
  trained.head().write(weights);
  ByteReader reader(weights.bytes(), to_string(from) + " weights");
  head->read(reader);
  return LearnedPolicy(std::move(config), trained.shared_representation(), std::move(head),
                       trained.camera());
}

LearnedPolicy LearnedPolicy::with_camera(std::shared_ptr<const ImageSource> camera) const {
  return LearnedPolicy(config_, representation_, head_, std::move(camera));
}

std::string LearnedPolicy::name() const {
  return to_string(config_.head) + "/" + config_.representation;
}

Eigen::VectorXd LearnedPolicy::action_vector(const Scene& observation,
                                             std::uint64_t noise_seed) const {
  observation.validate_observation();
  if (observation.history_length() != config_.history_length ||
      static_cast<int>(observation.hand_points.size()) != config_.hand_points ||
      static_cast<int>(observation.world_points.size()) != config_.world_points) {
    throw InvalidScene("observation with H = " + std::to_string(observation.history_length()) +
                       ", " + std::to_string(observation.hand_points.size()) + " eye-in-hand and " +
                       std::to_string(observation.world_points.size()) + " world points, but " +
                       name() + " was trained with H = " + std::to_string(config_.history_length) +
                       ", " + std::to_string(config_.hand_points) + " and " +
                       std::to_string(config_.world_points) +
                       ": give observations shaped like the training data");
  }
  // Step 1: the observation in the representation's frame (hand-centric: eq. (3)); an image
  // policy's points reach it only through its camera's image (image_source.hpp).
  Eigen::MatrixXd o;
  if (config_.observation == ObservationKind::image) {
    if (!camera_) {
      throw InvalidArgument(name() +
                            " is an image policy without its camera: load it with the "
                            "task's camera attached (experiments/insert3d_image.hpp)");
    }
    o = encode_image_observation(*representation_, *camera_, observation);
  } else {
    o = representation_->encode_observation(observation);
  }
  watch_layer("observation", 0, o);  // layer_watch.hpp
  // Step 2: the head, with noise from the caller's seed.
  std::mt19937_64 rng(noise_seed);
  Eigen::MatrixXd sampled = head_->sample_double(o, rng);
  watch_layer("action", 0, sampled);
  const Eigen::VectorXd a = sampled.col(0);
  if (!a.allFinite()) {
    throw NonFiniteAction(
        name() +
        " produced a non-finite action for this observation: is it far outside the "
        "training data (units, frames)?");
  }
  return a;
}

std::vector<RigidTransform> LearnedPolicy::act(const Scene& observation,
                                               std::uint64_t noise_seed) const {
  // Step 3: back to the world frame through the current hand pose T_0 (eq. (1) inverted).
  return representation_->decode_actions(action_vector(observation, noise_seed),
                                         observation.world_T_hand0());
}

}  // namespace handcentric::policy
