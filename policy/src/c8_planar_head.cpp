// Heads c8ddpm (the C8 baseline of Table 1, a stand-in for the 2D variant of Equivariant
// Diffusion Policy [7]), c8flow_planar, c8ddpm_avg and c8flow_avg; c8_planar.hpp has the
// encoding and the group action, c8_averaged.hpp the averaged sampler of the last two.
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
// So the trained c8ddpm model is equivariant only as far as the network learned it; [7]'s
// layers are equivariant exactly (docs/EXPERIMENTS.md, "The C8 baseline": not [7] itself).
// c8ddpm_avg trains the same network the same way and averages each DDIM step over the group
// instead (c8_averaged.hpp): exactly equivariant, with the modes of the unaveraged sampler;
// c8flow_avg does the same to c8flow_planar's Euler steps.
#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <string>

#include "ddpm_head.hpp"
#include "flow_head.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/policy/c8_averaged.hpp"
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
    encoded_set_ = {};
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

  // train_step's columns, with each column of the set encoded once (the same bits: the encoding
  // of the float32 column, moved in double, rounded).
  double train_step_on(const Minibatch& batch, std::mt19937_64& rng) override {
    encoded_set_.encode(batch.set_actions, batch.set_observations, actions_, observations_);
    const auto columns = static_cast<Eigen::Index>(batch.columns.size());
    a_.resize(actions_.planar_size(), columns);
    o_.resize(observations_.planar_size(), columns);
    for (Eigen::Index j = 0; j < columns; ++j) {
      const int k = static_cast<int>(rng() % 8);
      const Eigen::Index i = batch.columns[static_cast<std::size_t>(j)];
      c8::act_planar_float(k, centre_, encoded_set_.actions.col(i), actions_, a_.col(j));
      c8::act_planar_float(k, centre_, encoded_set_.observations.col(i), observations_, o_.col(j));
    }
    return inner_->train_step(a_, o_, rng);
  }

  Eigen::MatrixXd sample_double(const Eigen::MatrixXd& observations,
                                std::mt19937_64& rng) const override {
    if (averaged()) return c8::averaged_sample(*this, observations, rng);
    return sample(observations.cast<float>(), rng).cast<double>();
  }

  void set_learning_rate(double learning_rate) override {
    inner_->set_learning_rate(learning_rate);
  }
  void finish_training() override { inner_->finish_training(); }

  Eigen::MatrixXf sample(const Eigen::MatrixXf& observations, std::mt19937_64& rng) const override {
    if (averaged())
      return c8::averaged_sample(*this, observations.cast<double>(), rng).cast<float>();
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

  /// The inner DDPM (c8ddpm, c8ddpm_avg), else null.
  const DdpmHead* ddpm() const { return dynamic_cast<const DdpmHead*>(inner_.get()); }
  /// The inner rectified flow (c8flow_planar, c8flow_avg), else null.
  const FlowHead* flow() const { return dynamic_cast<const FlowHead*>(inner_.get()); }
  /// Whether sampling averages every step over C8 (c8ddpm_avg, c8flow_avg).
  bool averaged() const { return kind_ != trained_as(kind_); }
  const c8::Layout& action_layout() const { return actions_; }
  const c8::Layout& observation_layout() const { return observations_; }
  const Eigen::Vector2d& centre() const { return centre_; }

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
  // The planar encoding of every column of the trainer's float32 set, made on the first
  // train_step_on after prepare() and kept while the set is the same matrices: the encoding's
  // cos and sin were a tenth of a training step when every draw redid them.
  struct EncodedSet {
    const float* actions_data = nullptr;
    const float* observations_data = nullptr;
    Eigen::MatrixXd actions, observations;

    void encode(const Eigen::MatrixXf& set_actions, const Eigen::MatrixXf& set_observations,
                const c8::Layout& action_layout, const c8::Layout& observation_layout) {
      if (actions_data == set_actions.data() && observations_data == set_observations.data() &&
          actions.cols() == set_actions.cols() && observations.cols() == set_observations.cols())
        return;
      actions.resize(action_layout.planar_size(), set_actions.cols());
      observations.resize(observation_layout.planar_size(), set_observations.cols());
      for (Eigen::Index i = 0; i < set_actions.cols(); ++i) {
        actions.col(i) = c8::encode_planar(set_actions.col(i).cast<double>(), action_layout);
        observations.col(i) =
            c8::encode_planar(set_observations.col(i).cast<double>(), observation_layout);
      }
      actions_data = set_actions.data();
      observations_data = set_observations.data();
    }
  };

  Eigen::MatrixXf a_, o_;  // minibatch buffers
  EncodedSet encoded_set_;
};

// The sampler inside a planar C8 head as steps on normalized planar chunks: DDIM for the DDPM,
// Euler for the flow. The averaged sampler moves each step's input by the group.
struct StepSampler {
  const NetworkHead* network;  // its normalizers
  int steps;
  std::function<Eigen::MatrixXf(Eigen::Index, std::mt19937_64&)> initial_noise;
  std::function<void(Eigen::MatrixXf&, const Eigen::MatrixXf&, int)> step;
};

template <typename Inner>
StepSampler step_sampler(const Inner* inner, int steps,
                         void (Inner::*step)(Eigen::MatrixXf&, const Eigen::MatrixXf&, int) const) {
  return {inner, steps,
          [inner](Eigen::Index batch, std::mt19937_64& rng) {
            return inner->initial_noise(batch, rng);
          },
          [inner, step](Eigen::MatrixXf& x, const Eigen::MatrixXf& o, int i) {
            (inner->*step)(x, o, i);
          }};
}

}  // namespace

namespace c8 {

const std::vector<int>& all_elements() {
  static const std::vector<int> elements = {0, 1, 2, 3, 4, 5, 6, 7};
  return elements;
}

int heading_sector(const Eigen::VectorXd& planar_observation) {
  if (planar_observation.size() < kPlanarPoseSize) {
    throw InvalidArgument("heading_sector: a planar observation of length " +
                          std::to_string(planar_observation.size()) +
                          " has no pose block; give an encode_planar observation");
  }
  const double theta = std::atan2(planar_observation[4], planar_observation[3]);
  const int k = static_cast<int>(std::lround(theta / (std::numbers::pi / 4.0)));
  return ((k % 8) + 8) % 8;
}

Eigen::MatrixXd averaged_sample(const Head& head, const Eigen::MatrixXd& observations,
                                std::mt19937_64& rng, const std::vector<int>& elements) {
  const auto* planar = dynamic_cast<const C8PlanarHead*>(&head);
  const DdpmHead* ddpm = planar != nullptr ? planar->ddpm() : nullptr;
  const FlowHead* flow = planar != nullptr ? planar->flow() : nullptr;
  if (ddpm == nullptr && flow == nullptr) {
    throw InvalidArgument("the C8-averaged sampler needs a planar C8 head, got " +
                          to_string(head.kind()) + ": train with --head c8ddpm_avg or c8flow_avg");
  }
  const StepSampler inner = ddpm != nullptr
                                ? step_sampler(ddpm, ddpm->ddim_steps(), &DdpmHead::ddim_step)
                                : step_sampler(flow, flow->euler_steps(), &FlowHead::euler_step);
  if (elements.empty()) {
    throw InvalidArgument("the C8-averaged sampler needs at least one group element, got none");
  }
  for (int k : elements) {
    if (k < 0 || k > 7)
      throw InvalidArgument("C8 element " + std::to_string(k) + " is not one of 0..7");
  }
  const Layout& A = planar->action_layout();
  const Layout& O = planar->observation_layout();
  const Eigen::Vector2d& c = planar->centre();
  const Normalizer& action_normalizer = inner.network->action_normalizer();
  const auto n = static_cast<Eigen::Index>(elements.size());
  const Eigen::Index batch = observations.cols();

  // The start: the prior's mode moved onto C8's fixed points (the centre, heading vector 0; the
  // orbit mean is there up to rounding), plus the noise in raw units, turned by the element
  // nearest to the hand's heading so that the start moves with g (c8_averaged.hpp).
  Eigen::VectorXd mode = action_normalizer.mean();
  for (int i = 0; i < A.poses; ++i) {
    mode.segment<2>(kPlanarPoseSize * i) = c;
    mode.segment<2>(kPlanarPoseSize * i + 3).setZero();
  }
  const Eigen::MatrixXf noise = inner.initial_noise(batch, rng);  // normalized, drawn once
  std::vector<Eigen::VectorXd> x(static_cast<std::size_t>(batch));
  Eigen::MatrixXf o_images(O.planar_size(), batch * n);
  for (Eigen::Index j = 0; j < batch; ++j) {
    const Eigen::VectorXd o = encode_planar(observations.col(j), O);
    const Eigen::VectorXd start =
        mode + action_normalizer.scale().cwiseProduct(noise.col(j).cast<double>());
    x[static_cast<std::size_t>(j)] = act_planar(heading_sector(o), c, start, A);
    for (Eigen::Index e = 0; e < n; ++e)
      o_images.col(j * n + e) =
          act_planar(elements[static_cast<std::size_t>(e)], c, o, O).cast<float>();
  }
  inner.network->observation_normalizer().normalize(o_images);

  // Every step (DDIM or Euler) on all images at once (one network call), each image's result
  // moved back by its element's inverse and averaged:
  //   Phi(x, o) = 1/8 sum_k g_k^-1 phi(g_k x, g_k o).
  Eigen::MatrixXf x_images(A.planar_size(), batch * n);
  for (int i = 0; i < inner.steps; ++i) {
    for (Eigen::Index j = 0; j < batch; ++j) {
      for (Eigen::Index e = 0; e < n; ++e) {
        x_images.col(j * n + e) =
            act_planar(elements[static_cast<std::size_t>(e)], c, x[static_cast<std::size_t>(j)], A)
                .cast<float>();
      }
    }
    action_normalizer.normalize(x_images);
    inner.step(x_images, o_images, i);
    action_normalizer.denormalize(x_images);
    for (Eigen::Index j = 0; j < batch; ++j) {
      Eigen::VectorXd sum = Eigen::VectorXd::Zero(A.planar_size());
      for (Eigen::Index e = 0; e < n; ++e)
        sum += act_planar(-elements[static_cast<std::size_t>(e)], c,
                          x_images.col(j * n + e).cast<double>(), A);
      x[static_cast<std::size_t>(j)] = sum / static_cast<double>(n);
    }
  }
  Eigen::MatrixXd out(A.absolute_size(), batch);
  for (Eigen::Index j = 0; j < batch; ++j)
    out.col(j) = decode_planar(x[static_cast<std::size_t>(j)], A);
  return out;
}

}  // namespace c8

std::unique_ptr<Head> make_c8_planar_head(const PolicyConfig& config) {
  if (config.representation != "absolute") {
    throw InvalidArgument(
        "head " + to_string(config.head) + " encodes absolute poses, but the representation is '" +
        config.representation + "': use --repr absolute with --head " + to_string(config.head));
  }
  return std::make_unique<C8PlanarHead>(config);
}

}  // namespace handcentric::policy
