#pragma once
// Small configs and data sets for the policy suite: tiny networks and few steps, so that every
// training in the suite takes well under a second.
#include <random>
#include <vector>

#include "handcentric/core/sampling.hpp"
#include "handcentric/policy/config.hpp"
#include "handcentric/policy/dataset.hpp"

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

}  // namespace handcentric::test
