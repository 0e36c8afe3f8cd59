#pragma once
// LearnedPolicy: the outer policy of Sec. 3, steps 1-3, for any representation and any head:
//
//   world observation --representation.encode_observation--> vector
//                     --head.sample (noise from noise_seed)--> action vector
//                     --representation.decode_actions(., T_0)--> world chunk T_1..T_K
//
// With the hand_centric representation, the observation vector and the head's output do not
// change under a global g (Theorem 1), and decode maps them through g T_0: the chunk moves with
// g, eq. (4), whatever the network learned.
#include <memory>
#include <string>
#include <vector>

#include "handcentric/core/chunk_policy.hpp"
#include "handcentric/core/representation.hpp"
#include "handcentric/policy/config.hpp"
#include "handcentric/policy/head.hpp"
#include "handcentric/policy/image_source.hpp"

namespace handcentric::policy {

class LearnedPolicy final : public ChunkPolicy {
 public:
  /// Throws InvalidArgument for a null representation or head, or one whose name / kind does
  /// not match `config`. An image policy (config.observation = image) acts only once it has a
  /// camera of config's image shape (here or with_camera; a model file stores no camera, the
  /// task gives it: experiments/insert3d_image.hpp); a camera of another shape is an
  /// InvalidArgument, and a key-point policy ignores the camera.
  LearnedPolicy(PolicyConfig config, std::shared_ptr<const Representation> representation,
                std::shared_ptr<const Head> head, std::shared_ptr<const ImageSource> camera = {});

  /// The same policy looking through `camera` (the checks of the constructor).
  LearnedPolicy with_camera(std::shared_ptr<const ImageSource> camera) const;

  /// "<head>/<representation>", e.g. "flow/hand_centric".
  std::string name() const override;

  /// Throws InvalidArgument for an image policy without a camera, InvalidScene for an invalid
  /// observation or one whose H or point counts differ from
  /// training, and NonFiniteAction (an InvalidScene) for a non-finite output (an observation far
  /// outside the training data, or diverged weights).
  std::vector<RigidTransform> act(const Scene& observation,
                                  std::uint64_t noise_seed) const override;

  /// The head's raw action vector for `observation` (before decoding).
  Eigen::VectorXd action_vector(const Scene& observation, std::uint64_t noise_seed) const;

  const PolicyConfig& config() const { return config_; }
  const Representation& representation() const { return *representation_; }
  const Head& head() const { return *head_; }
  std::shared_ptr<const Head> shared_head() const { return head_; }
  std::shared_ptr<const Representation> shared_representation() const { return representation_; }
  /// The camera of an image policy; null for a key-point policy or one not given its camera yet.
  const std::shared_ptr<const ImageSource>& camera() const { return camera_; }

 private:
  PolicyConfig config_;
  std::shared_ptr<const Representation> representation_;
  std::shared_ptr<const Head> head_;
  std::shared_ptr<const ImageSource> camera_;
};

/// `trained` with head `kind`, which trains the same weights (trained_as, config.hpp): its
/// config with `kind`, its normalization, weights, representation and camera, `kind`'s sampler.
/// Bit for bit the policy that training `kind` on the same data and seed returns (a test checks
/// it), at no training cost: Table 1's c8_averaged row is c8_centre's network, sampled averaged.
/// Throws InvalidArgument naming both heads when `kind` trains differently.
LearnedPolicy with_head_kind(const LearnedPolicy& trained, HeadKind kind);

}  // namespace handcentric::policy
