#pragma once
// Private: the rectified-flow head (eq. (5)), also the base of the C8-symmetrized flow.
#include "network_head.hpp"

namespace handcentric::policy {

class FlowHead : public NetworkHead {
 public:
  using NetworkHead::NetworkHead;
  HeadKind kind() const override { return HeadKind::flow; }
  double train_step(const Eigen::MatrixXf& actions, const Eigen::MatrixXf& observations,
                    std::mt19937_64& rng) override;
  Eigen::MatrixXf sample(const Eigen::MatrixXf& observations, std::mt19937_64& rng) const override;

  /// The learned velocity in NORMALIZED coordinates, f_theta(x_t, t, o) of eq. (5), for
  /// normalized x (columns) and normalized o.
  Eigen::MatrixXf normalized_velocity(const Eigen::MatrixXf& x, double t,
                                      const Eigen::MatrixXf& o) const;

  /// The sampler's start in normalized units: noise_scale times standard normals, on the
  /// active action rows (sample_normalized's first draw).
  Eigen::MatrixXf initial_noise(Eigen::Index batch, std::mt19937_64& rng) const;
  /// Euler step n (0 .. euler_steps - 1) in place on normalized x for normalized o:
  /// x += f_theta(x, n / N, o) / N on the active rows, as sample_normalized steps.
  void euler_step(Eigen::MatrixXf& x, const Eigen::MatrixXf& o, int n) const;
  int euler_steps() const { return config_.euler_steps; }

 protected:
  /// The Euler sampler on normalized network observations (the MLP's observation rows).
  Eigen::MatrixXf sample_normalized(const Eigen::MatrixXf& o, std::mt19937_64& rng) const;
  /// Eq. (5)'s training sample for the normalized actions a_: noise_ (eps), t_, x_ = a(t) and
  /// target_ = a - eps.
  void draw_flow_sample(std::mt19937_64& rng);
  /// One step on already normalized actions a_ and observations o_ (the buffers).
  double train_normalized(std::mt19937_64& rng);
};

}  // namespace handcentric::policy
