#include "handcentric/props/random_network.hpp"

#include <cmath>
#include <random>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/props/noisy_policy.hpp"

namespace handcentric::props {

RandomMlp::RandomMlp(int inputs, const std::vector<int>& hidden, int outputs, std::uint64_t seed)
    : inputs_(inputs), outputs_(outputs) {
  std::vector<int> sizes = {inputs};
  sizes.insert(sizes.end(), hidden.begin(), hidden.end());
  sizes.push_back(outputs);
  for (int size : sizes) {
    if (size < 1)
      throw InvalidArgument("RandomMlp layer sizes must be positive, got " + std::to_string(size));
  }
  std::mt19937_64 rng(seed);
  for (std::size_t layer = 0; layer + 1 < sizes.size(); ++layer) {
    const double scale = 1.0 / std::sqrt(static_cast<double>(sizes[layer]));  // N(0, 1/fan_in)
    Eigen::MatrixXd W(sizes[layer + 1], sizes[layer]);
    Eigen::VectorXd b(sizes[layer + 1]);
    for (Eigen::Index i = 0; i < W.size(); ++i) W.data()[i] = scale * standard_normal(rng);
    for (Eigen::Index i = 0; i < b.size(); ++i) b(i) = scale * standard_normal(rng);
    weights_.push_back(std::move(W));
    biases_.push_back(std::move(b));
  }
}

Eigen::VectorXd RandomMlp::operator()(const Eigen::VectorXd& input) const {
  if (input.size() != inputs_) {
    throw InvalidArgument("RandomMlp expects " + std::to_string(inputs_) + " inputs, got " +
                          std::to_string(input.size()) + ": build it for this observation size");
  }
  Eigen::VectorXd x = input;
  for (std::size_t layer = 0; layer < weights_.size(); ++layer) {
    x = weights_[layer] * x + biases_[layer];
    if (layer + 1 < weights_.size()) x = x.array().tanh().matrix();
  }
  return x;
}

RandomOuterPolicy::RandomOuterPolicy(std::shared_ptr<const Representation> representation,
                                     int observation_dimension, int chunk_length,
                                     const std::vector<int>& hidden, std::uint64_t weight_seed)
    : representation_(std::move(representation)),
      chunk_length_(chunk_length),
      network_(observation_dimension + 6 * chunk_length, hidden, 6 * chunk_length, weight_seed) {
  if (!representation_ || !representation_->can_decode()) {
    throw InvalidArgument("RandomOuterPolicy needs a representation that decodes actions");
  }
  if (observation_dimension < 0 || chunk_length < 1) {
    throw InvalidArgument(
        "RandomOuterPolicy needs observation_dimension >= 0 and chunk_length >= 1, got " +
        std::to_string(observation_dimension) + " and " + std::to_string(chunk_length));
  }
}

std::string RandomOuterPolicy::name() const {
  return "random_outer_policy(" + representation_->name() + ")";
}

std::vector<RigidTransform> RandomOuterPolicy::act(const Scene& observation,
                                                   std::uint64_t noise_seed) const {
  observation.validate_observation();
  const Eigen::VectorXd o =
      representation_->encode_observation(observation);  // eq. (3) for hand_centric
  Eigen::VectorXd input(network_.inputs());
  if (o.size() + 6 * chunk_length_ != network_.inputs()) {
    throw InvalidArgument("RandomOuterPolicy: the observation encodes to " +
                          std::to_string(o.size()) + " numbers, the network was built for " +
                          std::to_string(network_.inputs() - 6 * chunk_length_));
  }
  input << o, fixed_noise(6 * chunk_length_, noise_seed);
  // Inverse of eq. (1) for hand_centric: a_k = T_0 ^R a_k (Theorem 1).
  return representation_->decode_actions(network_(input), observation.world_T_hand0());
}

}  // namespace handcentric::props
