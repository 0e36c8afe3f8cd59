#pragma once
// "Any network, untrained, random weights" (Theorem 1): a seeded random MLP and the outer
// policy of Sec. 3 around it, as a ChunkPolicy, so that equivariance can be checked for a
// network no one chose.
//
//   outer policy: o -> representation.encode_observation(o)              (eq. 3 for hand_centric)
//                   -> [that, eps] with eps the first 6K normals of mt19937_64(noise_seed)
//                   -> MLP -> representation.decode_actions(., T_0)      (inverse of eq. 1)
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "handcentric/core/chunk_policy.hpp"
#include "handcentric/core/representation.hpp"

namespace handcentric::props {

/// tanh hidden layers, linear output; weights and biases ~ N(0, 1/fan_in) from mt19937_64(seed).
class RandomMlp {
 public:
  /// Throws InvalidArgument for a non-positive size.
  RandomMlp(int inputs, const std::vector<int>& hidden, int outputs, std::uint64_t seed);
  int inputs() const { return inputs_; }
  int outputs() const { return outputs_; }
  /// Throws InvalidArgument for an input of the wrong length.
  Eigen::VectorXd operator()(const Eigen::VectorXd& input) const;

 private:
  int inputs_, outputs_;
  std::vector<Eigen::MatrixXd> weights_;
  std::vector<Eigen::VectorXd> biases_;
};

class RandomOuterPolicy final : public ChunkPolicy {
 public:
  /// Observations must encode to `observation_dimension` numbers; the policy outputs K poses.
  /// Throws InvalidArgument for a null representation, one that cannot decode, or bad sizes.
  RandomOuterPolicy(std::shared_ptr<const Representation> representation, int observation_dimension,
                    int chunk_length, const std::vector<int>& hidden, std::uint64_t weight_seed);
  std::string name() const override;
  std::vector<RigidTransform> act(const Scene& observation,
                                  std::uint64_t noise_seed) const override;

 private:
  std::shared_ptr<const Representation> representation_;
  int chunk_length_;
  RandomMlp network_;
};

}  // namespace handcentric::props
