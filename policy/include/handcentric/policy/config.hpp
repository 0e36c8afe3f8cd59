#pragma once
// PolicyConfig: everything that defines a learned policy besides its weights; stored in model
// files as "key=value" lines (to_text / from_text).
#include <cstdint>
#include <string>

namespace handcentric::policy {

/// The generative head (Sec. 2.3 and App. B): rectified flow, DDPM, CVAE, or the
/// C8-symmetrized flow (the analogue of Equivariant Diffusion Policy [7]).
enum class HeadKind { flow, ddpm, cvae, c8flow };

enum class Activation { silu, relu };

/// The learning rate over training (trainer.hpp, learning_rate_at): constant, or a cosine
/// decay from learning_rate at the first step towards 0 at the last (Loshchilov & Hutter, SGDR),
/// the default.
enum class LearningRateSchedule { constant, cosine };

/// "flow", "ddpm", "cvae", "c8flow".
std::string to_string(HeadKind kind);
/// Throws InvalidArgument naming the value and the valid names.
HeadKind parse_head(const std::string& name);
std::string to_string(Activation activation);
Activation parse_activation(const std::string& name);
/// "constant", "cosine".
std::string to_string(LearningRateSchedule schedule);
/// Throws InvalidArgument naming the value and the valid names.
LearningRateSchedule parse_schedule(const std::string& name);

struct PolicyConfig {
  HeadKind head = HeadKind::flow;
  std::string representation = "hand_centric";
  int chunk_length = 16;   ///< K
  int history_length = 2;  ///< H
  // Set from the training data by the trainer (the observation layout, see representation.hpp).
  int hand_points = 0;
  int world_points = 0;
  int action_dimension = 0;
  int observation_dimension = 0;
  // Network: hidden_layers layers of hidden_width, then a linear output.
  int hidden_width = 256;
  int hidden_layers = 3;
  Activation activation = Activation::silu;
  int time_embedding = 16;  ///< sinusoidal features of t (even, >= 2), or 0 for t itself
  // Training.
  int steps = 5000;
  int batch_size = 256;
  double learning_rate = 1e-3;  ///< the peak: at every step (constant) or at the first (cosine)
  /// cosine by default: on 100 peg-in-hole demos (H = 0, 60000 steps) flow / hand_centric
  /// succeeds in 40 of 50 tuning rollouts with it and 13 of 50 with a constant rate (docs/SIM.md).
  LearningRateSchedule lr_schedule = LearningRateSchedule::cosine;
  double weight_decay = 0.0;  ///< decoupled (AdamW)
  double gradient_clip = 1.0;  ///< global L2 norm; 0 disables
  /// Keep the exponential moving average of the weights (weight_average.hpp) and put it in the
  /// model: 0 = off (the default), 0.999 is usual.
  double ema_decay = 0.0;
  // Sampling and heads.
  int euler_steps = 10;          ///< rectified flow, eq. (5)
  int ddpm_train_steps = 100;    ///< DDPM diffusion steps
  int ddim_steps = 10;           ///< DDIM sampling steps
  int cvae_latent = 16;
  double cvae_kl_weight = 1e-2;

  /// Throws InvalidArgument naming the first out-of-range field and its valid range.
  void validate() const;
  std::string to_text() const;
  /// Parses to_text() output; throws InvalidArgument for an unknown key or a bad value.
  static PolicyConfig from_text(const std::string& text);
};

}  // namespace handcentric::policy
