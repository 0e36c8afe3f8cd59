#pragma once
// Head: the generative model that maps an observation vector to an action vector, trained on
// (action, observation) pairs that a Representation produced. Every head takes RAW vectors
// (one per column) and owns its normalization, so the outer policy is the same for all:
//
//   flow   : rectified flow matching, eq. (5), Euler sampler            (Sec. 2.3)
//   ddpm   : epsilon-prediction diffusion, DDIM sampler                  (App. B ablation)
//   cvae   : conditional VAE                                             (App. B ablation)
//   c8flow : rectified flow whose sampler averages the velocity over the 8 rotations about world
//            z through the origin, f(x) = 1/8 sum_g g_* f(g^-1 x), on ABSOLUTE actions: the
//            analogue of Equivariant Diffusion Policy [7] (not [7] itself; see c8_action.hpp)
//   c8ddpm : DDPM on planar poses (x, y, z, cos, sin) trained on the C8 orbit of its data about
//            config.c8_centre_*: Table 1's stand-in for [7] (c8_planar.hpp)
//   c8ddpm_avg : c8ddpm's network, trained the same way, whose DDIM step is averaged over C8
//            at every step: exactly C8-equivariant whatever the weights (c8_averaged.hpp)
//   c8flow_planar, c8flow_avg : the same two with the rectified flow in place of the DDPM
#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <random>
#include <span>

#include "handcentric/policy/binary_io.hpp"
#include "handcentric/policy/config.hpp"

namespace handcentric::policy {

/// A minibatch as the trainer draws it: the columns `columns` of the whole training set
/// (`set_actions`, `set_observations`: float32, the trainer's copy of what prepare() saw), and
/// those columns copied out, in that order (`actions`, `observations`), unless the head
/// reads_the_set() (then they are not filled).
struct Minibatch {
  const Eigen::MatrixXf& set_actions;
  const Eigen::MatrixXf& set_observations;
  std::span<const Eigen::Index> columns;
  const Eigen::MatrixXf& actions;
  const Eigen::MatrixXf& observations;
};

class Head {
 public:
  virtual ~Head() = default;
  virtual HeadKind kind() const = 0;

  /// Fits the normalization statistics from the whole training set (actions: action_dimension
  /// x N, observations: observation_dimension x N) and initializes the weights from `rng`.
  virtual void prepare(const Eigen::MatrixXd& actions, const Eigen::MatrixXd& observations,
                       std::mt19937_64& rng) = 0;

  /// One optimizer step on a minibatch of raw columns; returns the minibatch loss before it.
  virtual double train_step(const Eigen::MatrixXf& actions, const Eigen::MatrixXf& observations,
                            std::mt19937_64& rng) = 0;

  /// train_step on a minibatch the trainer drew (what the trainer calls). A head that applies a
  /// fixed transform to each raw column (the planar C8 heads' encoding) overrides it to compute
  /// the transform once per column of the training set rather than once per draw.
  virtual double train_step_on(const Minibatch& batch, std::mt19937_64& rng) {
    return train_step(batch.actions, batch.observations, rng);
  }
  /// True when train_step_on reads only the set's columns (batch.set_actions,
  /// batch.set_observations, batch.columns), so the trainer need not copy the batch out.
  virtual bool reads_the_set() const { return false; }
  /// The optimizer's learning rate for the next train_step calls (the trainer's schedule).
  virtual void set_learning_rate(double learning_rate) = 0;
  /// Threads the next train_step calls may use (1 until set). The image heads run a step's
  /// slices on them (slice_team.hpp: the same weights, bit for bit, for any number); the others
  /// train on one. Throws InvalidArgument for threads outside 1..SliceTeam::kMaxThreads.
  virtual void set_threads(int threads);

  /// Called once after the last train_step: with config.ema_decay > 0 the head's weights
  /// become their moving average (weight_average.hpp), which is what sample() and write() use.
  virtual void finish_training() = 0;

  /// One raw action vector per raw observation column; all noise from `rng`.
  virtual Eigen::MatrixXf sample(const Eigen::MatrixXf& observations,
                                 std::mt19937_64& rng) const = 0;

  /// sample() in double, from observations as the representation encoded them (what
  /// LearnedPolicy calls). By default the observations are rounded to float32 and the actions
  /// are sample()'s. c8ddpm_avg moves the observations by C8 before rounding and returns its
  /// average in double: o and g o rounded first, or g a and a(g o) rounded after, would differ
  /// by float32 rounding of world coordinates, an equivariance error far above double rounding.
  virtual Eigen::MatrixXd sample_double(const Eigen::MatrixXd& observations,
                                        std::mt19937_64& rng) const {
    return sample(observations.cast<float>(), rng).cast<double>();
  }

  /// Normalization statistics and weights (the config is stored by the model file).
  virtual void write(ByteWriter& out) const = 0;
  /// Reads what write() wrote, checking every length against the config.
  virtual void read(ByteReader& in) = 0;
};

/// The head `config.head` for the dimensions in `config` (action_dimension and
/// observation_dimension must be set). Throws InvalidArgument for a bad config, and for c8flow
/// or c8ddpm with a representation other than "absolute".
std::unique_ptr<Head> make_head(const PolicyConfig& config);

class ConvEncoder;
/// The image encoder of an image policy's head (config.observation = image), to inspect its
/// weights; null for every other head.
const ConvEncoder* image_encoder(const Head& head);

/// The number of float32 weights make_head(config) holds (and a model file stores), computed
/// without allocating anything. Throws InvalidArgument for a config make_head refuses.
std::uint64_t parameter_count(const PolicyConfig& config);

}  // namespace handcentric::policy
