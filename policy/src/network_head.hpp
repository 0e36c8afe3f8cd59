#pragma once
// Private: what the flow and DDPM heads share. One MLP that sees [x, time features, observation],
// the two normalizers, Adam, and the minibatch buffers (allocated once, reused every step).
#include <Eigen/Core>
#include <random>
#include <span>

#include "handcentric/policy/adam.hpp"
#include "handcentric/policy/head.hpp"
#include "handcentric/policy/mlp.hpp"
#include "handcentric/policy/normalizer.hpp"
#include "handcentric/policy/weight_average.hpp"

namespace handcentric::policy {

class NetworkHead : public Head {
 public:
  explicit NetworkHead(const PolicyConfig& config);
  /// With an MLP that sees `network_observation_rows` observation rows rather than
  /// config.observation_dimension (an image head's features in place of its pixels).
  NetworkHead(const PolicyConfig& config, int network_observation_rows);
  void prepare(const Eigen::MatrixXd& actions, const Eigen::MatrixXd& observations,
               std::mt19937_64& rng) override;
  void write(ByteWriter& out) const override;
  void read(ByteReader& in) override;
  void set_learning_rate(double learning_rate) override { adam_.set_learning_rate(learning_rate); }
  void finish_training() override;

  const Mlp& network() const { return network_; }
  const Normalizer& action_normalizer() const { return action_normalizer_; }
  const Normalizer& observation_normalizer() const { return observation_normalizer_; }

 protected:
  /// Rows of the network input: [x (action_dimension), time features, observation].
  int time_rows() const;
  /// Writes [x; features(t_j); o] into `input` (columns j); resizes it once per batch size.
  void assemble(const Eigen::MatrixXf& x, const Eigen::VectorXd& t, const Eigen::MatrixXf& o,
                Eigen::MatrixXf& input) const;
  /// The same with column j's time features given as features.col(times[j]) (the DDPM's
  /// discrete times, whose features are computed once, not once per draw).
  void assemble(const Eigen::MatrixXf& x, const Eigen::MatrixXf& features,
                std::span<const int> times, const Eigen::MatrixXf& o, Eigen::MatrixXf& input) const;
  /// Mean squared error of the last network_.forward() output against `target`, its backward
  /// pass, clipping and the Adam step. Returns the loss.
  double regress(const Eigen::MatrixXf& output, const Eigen::MatrixXf& target);

  PolicyConfig config_;
  Normalizer action_normalizer_, observation_normalizer_;
  Mlp network_;
  Adam adam_;
  WeightAverage average_;
  // Minibatch buffers.
  Eigen::MatrixXf a_, o_, noise_, x_, target_, input_, d_output_;
  Eigen::VectorXd t_;
};

}  // namespace handcentric::policy
