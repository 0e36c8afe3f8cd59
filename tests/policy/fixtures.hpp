#pragma once
// Small configs and data sets for the policy suite: tiny networks and few steps, so that every
// training in the suite takes well under a second.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "handcentric/core/sampling.hpp"
#include "handcentric/policy/config.hpp"
#include "handcentric/policy/dataset.hpp"
#include "handcentric/policy/image_source.hpp"

namespace handcentric::test {

/// A 2-layer, 32-wide network, batch 64, K = 4, H = 2, sampling from the whole distribution.
inline policy::PolicyConfig small_config(policy::HeadKind head, const std::string& representation,
                                         int steps) {
  policy::PolicyConfig config;
  config.head = head;
  config.representation = representation;
  config.chunk_length = 4;
  config.history_length = 2;
  config.hidden_width = 32;
  config.hidden_layers = 2;
  config.time_embedding = 8;
  config.steps = steps;
  config.batch_size = 64;
  config.learning_rate = 3e-3;
  config.cvae_latent = 4;
  config.noise_scale = 1.0;  // the suite checks the learned distribution, not only its mode
  return config;
}

/// `count` random scenes with H = 2, K = 4, two eye-in-hand points, no world points.
inline std::vector<Scene> small_scenes(int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Scene> scenes;
  for (int i = 0; i < count; ++i) scenes.push_back(random_scene(rng, 2, 4, 2, 0, 2.0));
  return scenes;
}

/// A data set with a one-number constant observation and 2D actions drawn from two modes,
/// (-1, 0.5) and (1, -0.5), with a spread of 0.02: the toy target of the issue.
inline policy::Dataset two_mode_data(int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  policy::Dataset data;
  data.actions.resize(2, count);
  data.observations = Eigen::MatrixXd::Zero(1, count);
  for (int j = 0; j < count; ++j) {
    const double sign = j % 2 == 0 ? -1.0 : 1.0;
    data.actions(0, j) = sign + 0.02 * standard_normal(rng);
    data.actions(1, j) = -0.5 * sign + 0.02 * standard_normal(rng);
  }
  return data;
}

/// A small image policy: small_config with an image of the hand points through a 2-layer encoder.
inline policy::PolicyConfig small_image_config(const std::string& representation, int steps) {
  policy::PolicyConfig config = small_config(policy::HeadKind::flow, representation, steps);
  config.observation = policy::ObservationKind::image;
  config.encoder = "4,8";
  return config;
}

/// A camera for the policy suite (the tasks' cameras live in experiments/): one 8 x 10 channel,
/// a blob of light where each point falls, seen from the hand (eye_in_hand: the eye-in-hand
/// points as they are, what a hand camera sees) or from the world (the points at T_0 p, a camera
/// fixed in the world, whose image moves with g: a planted fault for Theorem 1).
class BlobCamera final : public policy::ImageSource {
 public:
  explicit BlobCamera(bool eye_in_hand = true) : eye_in_hand_(eye_in_hand) {}
  std::string name() const override {
    return eye_in_hand_ ? "blob camera (hand)" : "blob camera (world)";
  }
  policy::ImageShape shape() const override { return {1, 8, 10}; }
  void render(const Scene& observation, Eigen::Ref<Eigen::VectorXd> image) const override {
    image.setZero();
    for (const Eigen::Vector3d& hand_p : observation.hand_points) {
      const Eigen::Vector3d p = eye_in_hand_ ? hand_p : observation.world_T_hand0() * hand_p;
      for (int row = 0; row < 8; ++row) {
        for (int col = 0; col < 10; ++col) {
          const double dy = p.y() - (row - 3.5) * 0.5, dx = p.x() - (col - 4.5) * 0.5;
          image[row * 10 + col] += std::exp(-(dx * dx + dy * dy) - 0.1 * p.z() * p.z());
        }
      }
    }
  }

 private:
  bool eye_in_hand_;
};

}  // namespace handcentric::test
