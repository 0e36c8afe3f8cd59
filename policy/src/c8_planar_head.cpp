// Heads c8ddpm (the C8 baseline of Table 1, a stand-in for the 2D variant of Equivariant
// Diffusion Policy [7]) and c8flow_planar; c8_planar.hpp has the encoding and the group action.
//
//   encoding : absolute actions and observations -> planar ones (x, y, z, cos, sin per pose;
//              eye-in-hand points as they are), decoded back with theta = atan2(sin, cos);
//   training : DDPM (ddpm_head.cpp), as [7] uses, on the 8x augmented data: prepare() fits the
//              normalization on every sample's whole C8 orbit about the centre, and each
//              minibatch column is rotated by a uniformly drawn element of C8, which is drawing
//              from the augmented set;
//   c8flow_planar: the same with the rectified flow inside (flow_head.cpp), a control that
//              separates the C8 encoding from the DDPM (docs/EXPERIMENTS.md);
//   sampling : the DDPM's DDIM sampler on the encoded observation, started at noise_scale times
//              the prior's noise (0: its mode, as the flow heads do; PolicyConfig::noise_scale).
//
// Symmetrization by augmentation, not by averaging at inference: the minimizer of the training
// loss over ALL functions is C8-equivariant when the data is C8-invariant, so the augmented
// loss asks a plain MLP for the function class an equivariant network has by construction.
// Averaging the 8 sampled chunks g_k s(g_k^-1 o) would make the sampler exactly equivariant,
// but an average of two different modes is a chunk no demo has, and the hole allows 0.05 cm.
// So the trained model is equivariant only as far as the network learned it; [7]'s layers
// are equivariant exactly (docs/EXPERIMENTS.md, "The C8 baseline": not [7] itself).
#include <memory>

#include "handcentric/core/errors.hpp"
#include "handcentric/policy/c8_planar.hpp"
#include "handcentric/policy/head.hpp"

namespace handcentric::policy {

namespace {

class C8PlanarHead final : public Head {
 public:
  explicit C8PlanarHead(const PolicyConfig& config)
      : actions_(c8::action_layout(config)),
        observations_(c8::observation_layout(config)),
        centre_(c8::centre_of(config)),
        kind_(config.head),
        inner_(make_head(c8::inner_config(config))) {}

  HeadKind kind() const override { return kind_; }

  void prepare(const Eigen::MatrixXd& actions, const Eigen::MatrixXd& observations,
               std::mt19937_64& rng) override {
    if (actions.cols() == 0) throw InvalidArgument(to_string(kind_) + ": no training samples");
    Eigen::MatrixXd a(actions_.planar_size(), actions.cols());
    Eigen::MatrixXd o(observations_.planar_size(), observations.cols());
    for (Eigen::Index j = 0; j < actions.cols(); ++j) {
      a.col(j) = c8::encode_planar(actions.col(j), actions_);
      o.col(j) = c8::encode_planar(observations.col(j), observations_);
    }
    inner_->prepare(c8::orbit(a, centre_, actions_), c8::orbit(o, centre_, observations_), rng);
  }

  double train_step(const Eigen::MatrixXf& actions, const Eigen::MatrixXf& observations,
                    std::mt19937_64& rng) override {
    a_.resize(actions_.planar_size(), actions.cols());
    o_.resize(observations_.planar_size(), observations.cols());
    for (Eigen::Index j = 0; j < actions.cols(); ++j) {
      const int k = static_cast<int>(rng() % 8);
      a_.col(j) = moved(k, actions.col(j), actions_);
      o_.col(j) = moved(k, observations.col(j), observations_);
    }
    return inner_->train_step(a_, o_, rng);
  }

  void set_learning_rate(double learning_rate) override {
    inner_->set_learning_rate(learning_rate);
  }
  void finish_training() override { inner_->finish_training(); }

  Eigen::MatrixXf sample(const Eigen::MatrixXf& observations, std::mt19937_64& rng) const override {
    Eigen::MatrixXf o(observations_.planar_size(), observations.cols());
    for (Eigen::Index j = 0; j < observations.cols(); ++j)
      o.col(j) = moved(0, observations.col(j), observations_);
    const Eigen::MatrixXf planar = inner_->sample(o, rng);
    Eigen::MatrixXf out(actions_.absolute_size(), planar.cols());
    for (Eigen::Index j = 0; j < planar.cols(); ++j) {
      out.col(j) = c8::decode_planar(planar.col(j).cast<double>(), actions_).cast<float>();
    }
    return out;
  }

  // The centre is in the config, which the model file stores; the weights are the inner DDPM's.
  void write(ByteWriter& out) const override { inner_->write(out); }
  void read(ByteReader& in) override { inner_->read(in); }

 private:
  // g_k encode(v) as float32, for a raw absolute column.
  Eigen::VectorXf moved(int k, const Eigen::Ref<const Eigen::VectorXf>& absolute,
                        const c8::Layout& layout) const {
    return c8::act_planar(k, centre_, c8::encode_planar(absolute.cast<double>(), layout), layout)
        .cast<float>();
  }

  c8::Layout actions_, observations_;
  Eigen::Vector2d centre_;
  HeadKind kind_;
  std::unique_ptr<Head> inner_;
  Eigen::MatrixXf a_, o_;  // minibatch buffers
};

}  // namespace

std::unique_ptr<Head> make_c8_planar_head(const PolicyConfig& config) {
  if (config.representation != "absolute") {
    throw InvalidArgument(
        "head " + to_string(config.head) + " encodes absolute poses, but the representation is '" +
        config.representation + "': use --repr absolute with --head " + to_string(config.head));
  }
  return std::make_unique<C8PlanarHead>(config);
}

}  // namespace handcentric::policy
