#pragma once
// Private: the DDPM head (ddpm_head.cpp has the equations), visible to the C8 heads, whose
// averaged sampler (c8_averaged.hpp) runs one DDIM step at a time on the group's images.
#include <Eigen/Core>
#include <random>
#include <vector>

#include "network_head.hpp"

namespace handcentric::policy {

class DdpmHead final : public NetworkHead {
 public:
  explicit DdpmHead(const PolicyConfig& config);
  HeadKind kind() const override { return HeadKind::ddpm; }
  void prepare(const Eigen::MatrixXd& actions, const Eigen::MatrixXd& observations,
               std::mt19937_64& rng) override;
  void write(ByteWriter& out) const override;
  void read(ByteReader& in) override;
  double train_step(const Eigen::MatrixXf& actions, const Eigen::MatrixXf& observations,
                    std::mt19937_64& rng) override;
  Eigen::MatrixXf sample(const Eigen::MatrixXf& observations, std::mt19937_64& rng) const override;

  /// x_T in normalized coordinates: noise_scale times standard normals (0 on constant
  /// dimensions), one column per observation, drawn from `rng`.
  Eigen::MatrixXf initial_noise(Eigen::Index batch, std::mt19937_64& rng) const;
  /// DDIM step i (0 .. ddim_steps - 1) in place on normalized x, for normalized observations o
  /// (one column each): after the last step x is the normalized chunk.
  void ddim_step(Eigen::MatrixXf& x, const Eigen::MatrixXf& o, int i) const;
  int ddim_steps() const { return config_.ddim_steps; }

 private:
  std::vector<double> alpha_bar_;
  /// Column k: the time features of step k, of t = (k + 1) / T.
  Eigen::MatrixXf time_features_;
  std::vector<int> steps_;      ///< the minibatch's steps k
  float clip_ = 1.0f;           ///< max |normalized training action|, at least 1
  float initial_noise_ = 1.0f;  ///< scale of x_T; 0 starts DDIM at the prior's mode
};

}  // namespace handcentric::policy
