// The C8-symmetrized rectified flow (c8_flow.hpp, c8_action.hpp): the analogue of Equivariant
// Diffusion Policy [7] for the Table 1 baseline.
//
//   training : rectified flow (eq. (5)) on C8-augmented pairs (g a, g o), g uniform in C8;
//   sampling : Euler steps on the frame-averaged field F in raw absolute coordinates, which makes
//              the sampler's ODE exactly C8-equivariant whatever the network learned;
//   noise    : x_0 = mean + scale * eps with statistics of the C8 orbit of the training set,
//              symmetrized so that mean_x = mean_y = 0 and scale_x = scale_y in every 3-block
//              that C8 rotates: the translation part of the source distribution is C8-invariant.
#include <string>

#include "flow_head.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/policy/c8_action.hpp"
#include "handcentric/policy/c8_flow.hpp"
#include "handcentric/policy/gaussian.hpp"

namespace handcentric::policy {
namespace {

// Orbit statistics of the columns of `data` under C8, acted on by `act`, then symmetrized in
// the 3-blocks [begin, end) that C8 rotates.
template <typename Act>
Normalizer orbit_normalizer(const Eigen::MatrixXd& data, Act act, Eigen::Index rotated_end) {
  if (data.cols() == 0) throw InvalidArgument("c8flow: no training samples");
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(data.rows()),
                  sum_sq = Eigen::VectorXd::Zero(data.rows());
  for (Eigen::Index j = 0; j < data.cols(); ++j) {
    for (int k = 0; k < 8; ++k) {
      const Eigen::VectorXd v = act(c8::rotation(k), Eigen::VectorXd(data.col(j)));
      sum += v;
      sum_sq += v.cwiseAbs2();
    }
  }
  const double n = 8.0 * static_cast<double>(data.cols());
  Eigen::VectorXd mean = sum / n;
  Eigen::VectorXd variance = (sum_sq / n - mean.cwiseAbs2()).cwiseMax(0.0);
  for (Eigen::Index i = 0; i + 3 <= rotated_end; i += 3) {
    const double second_moment = 0.5 * (sum_sq[i] + sum_sq[i + 1]) / n;  // about the z axis
    mean[i] = mean[i + 1] = 0.0;
    variance[i] = variance[i + 1] = second_moment;
  }
  Eigen::VectorXd scale(data.rows()), active(data.rows());
  for (Eigen::Index i = 0; i < scale.size(); ++i) {
    const double s = std::sqrt(variance[i]);
    const bool constant = s < 1e-8 * (1.0 + std::abs(mean[i]));
    scale[i] = constant ? 1.0 : s;
    active[i] = constant ? 0.0 : 1.0;
  }
  return Normalizer(mean, scale, active);
}

class C8FlowHead final : public FlowHead {
 public:
  using FlowHead::FlowHead;
  HeadKind kind() const override { return HeadKind::c8flow; }

  void prepare(const Eigen::MatrixXd& actions, const Eigen::MatrixXd& observations,
               std::mt19937_64& rng) override {
    action_normalizer_ = orbit_normalizer(
        actions,
        [](const Eigen::Matrix3d& R, const Eigen::VectorXd& a) { return c8::act_on_actions(R, a); },
        actions.rows());
    const int H = config_.history_length, hand = config_.hand_points;
    observation_normalizer_ = orbit_normalizer(
        observations,
        [H, hand](const Eigen::Matrix3d& R, const Eigen::VectorXd& o) {
          return c8::act_on_observation(R, o, H, hand);
        },
        6 * (H + 1));
    network_.initialize(rng);
  }

  double train_step(const Eigen::MatrixXf& actions, const Eigen::MatrixXf& observations,
                    std::mt19937_64& rng) override {
    a_.resize(actions.rows(), actions.cols());
    o_.resize(observations.rows(), observations.cols());
    for (Eigen::Index j = 0; j < actions.cols(); ++j) {
      const Eigen::Matrix3d R = c8::rotation(static_cast<int>(rng() % 8));
      a_.col(j) = c8::act_on_actions(R, actions.col(j).cast<double>()).cast<float>();
      o_.col(j) = c8::act_on_observation(R, observations.col(j).cast<double>(),
                                         config_.history_length, config_.hand_points)
                      .cast<float>();
    }
    action_normalizer_.normalize(a_);
    observation_normalizer_.normalize(o_);
    return train_normalized(rng);
  }

  /// f (raw coordinates) at the 8 points (g_k^{-1} x, g_k^{-1} o), pushed forward and averaged.
  Eigen::VectorXd velocity(const Eigen::VectorXd& x, const Eigen::VectorXd& o, double t,
                           bool symmetrized) const {
    const int copies = symmetrized ? 8 : 1;
    std::vector<Eigen::VectorXd> points(copies);
    Eigen::MatrixXf xs(x.size(), copies), os(o.size(), copies);
    for (int k = 0; k < copies; ++k) {
      const Eigen::Matrix3d R_inverse = c8::rotation(-k);
      points[k] = c8::act_on_actions(R_inverse, x);
      xs.col(k) = points[k].cast<float>();
      os.col(k) = c8::act_on_observation(R_inverse, o, config_.history_length, config_.hand_points)
                      .cast<float>();
    }
    action_normalizer_.normalize(xs);
    observation_normalizer_.normalize(os);
    Eigen::MatrixXf v = normalized_velocity(xs, t, os);
    v.array().colwise() *= action_normalizer_.active_float().array();
    const Eigen::VectorXd scale = action_normalizer_.scale();
    Eigen::VectorXd sum = Eigen::VectorXd::Zero(x.size());
    for (int k = 0; k < copies; ++k) {
      const Eigen::VectorXd raw_velocity = scale.cwiseProduct(v.col(k).cast<double>());
      sum += c8::push_velocity(c8::rotation(k), points[k], raw_velocity);
    }
    return sum / copies;
  }

  Eigen::MatrixXf sample(const Eigen::MatrixXf& observations, std::mt19937_64& rng) const override {
    Eigen::MatrixXf x0(config_.action_dimension, observations.cols());
    fill_standard_normal(rng, x0);
    x0.array().colwise() *=
        action_normalizer_.active_float().array() * static_cast<float>(config_.noise_scale);
    action_normalizer_.denormalize(x0);
    Eigen::MatrixXf out(x0.rows(), x0.cols());
    const int steps = config_.euler_steps;
    for (Eigen::Index j = 0; j < observations.cols(); ++j) {
      Eigen::VectorXd x = x0.col(j).cast<double>();
      const Eigen::VectorXd o = observations.col(j).cast<double>();
      for (int n = 0; n < steps; ++n) {
        x += velocity(x, o, static_cast<double>(n) / steps, true) / steps;  // Euler step on F
      }
      out.col(j) = x.cast<float>();
    }
    return out;
  }
};

}  // namespace

std::unique_ptr<Head> make_c8_flow_head(const PolicyConfig& config) {
  if (config.representation != "absolute") {
    throw InvalidArgument("head c8flow acts on absolute actions, but the representation is '" +
                          config.representation + "': use --repr absolute with --head c8flow");
  }
  return std::make_unique<C8FlowHead>(config);
}

Eigen::VectorXd c8_velocity(const Head& head, const Eigen::VectorXd& x, const Eigen::VectorXd& o,
                            double t, bool symmetrized) {
  const auto* c8_head = dynamic_cast<const C8FlowHead*>(&head);
  if (c8_head == nullptr) {
    throw InvalidArgument("c8_velocity needs a c8flow head, got " + to_string(head.kind()));
  }
  return c8_head->velocity(x, o, t, symmetrized);
}

}  // namespace handcentric::policy
