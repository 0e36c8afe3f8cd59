#pragma once
// PolicyConfig: everything that defines a learned policy besides its weights; stored in model
// files as "key=value" lines (to_text / from_text).
#include <cstdint>
#include <string>
#include <vector>

namespace handcentric::policy {

/// The generative head (Sec. 2.3 and App. B): rectified flow, DDPM, CVAE, the C8-symmetrized
/// flow on absolute rotation vectors, or the C8 baseline of Table 1 (c8_planar.hpp): DDPM on
/// planar poses, trained on the C8 orbit of its data (stand-ins for Equivariant-DiffPo [7]),
/// or the same with the rectified flow (c8flow_planar, a control for the DDPM), or c8ddpm with
/// its denoising step averaged over C8 at every DDIM step, C8-equivariant by construction
/// (c8ddpm_avg, c8_averaged.hpp), or c8flow_planar with its Euler step averaged so
/// (c8flow_avg).
enum class HeadKind { flow, ddpm, cvae, c8flow, c8ddpm, c8flow_planar, c8ddpm_avg, c8flow_avg };

enum class Activation { silu, relu };

/// The learning rate over training (trainer.hpp, learning_rate_at): constant, or a cosine
/// decay from learning_rate at the first step towards 0 at the last (Loshchilov & Hutter, SGDR),
/// the default.
enum class LearningRateSchedule { constant, cosine };

/// What the DDPM head's network predicts from the noised chunk x_k (ddpm_head.cpp): the noise
/// (epsilon, Ho et al. 2020) or the clean chunk itself (sample, x0; Diffusion Policy offers both
/// as `prediction_type`). Either gives the other through x_k = sqrt(abar) x0 + sqrt(1 - abar) eps.
enum class DdpmPrediction { epsilon, sample };

/// What the network sees besides the representation's proprioception: the key points the
/// representation encodes (key_points), or an image of the hand camera (image) passed through a
/// ConvEncoder (conv_encoder.hpp) trained end to end with the head; the points are then left out
/// of the observation vector and only drive the camera (image_source.hpp).
enum class ObservationKind { key_points, image };

/// "flow", "ddpm", "cvae", "c8flow", "c8ddpm", "c8flow_planar", "c8ddpm_avg", "c8flow_avg".
std::string to_string(HeadKind kind);
/// Throws InvalidArgument naming the value and the valid names.
HeadKind parse_head(const std::string& name);
/// c8ddpm, c8flow_planar, c8ddpm_avg or c8flow_avg: the heads on the planar C8 encoding, which
/// read c8_centre_*.
bool is_c8_planar(HeadKind kind);
/// The head whose training `kind` runs, bit for bit: c8ddpm for c8ddpm_avg and c8flow_planar for
/// c8flow_avg (the same network, loss, data and random draws; only the sampler differs,
/// c8_averaged.hpp), else `kind`. Two
/// configs that differ only in heads with one trained_as train the same weights, so Table 1
/// trains them once (with_head_kind in learned_policy.hpp).
HeadKind trained_as(HeadKind kind);
std::string to_string(Activation activation);
Activation parse_activation(const std::string& name);
/// "constant", "cosine".
std::string to_string(LearningRateSchedule schedule);
/// Throws InvalidArgument naming the value and the valid names.
LearningRateSchedule parse_schedule(const std::string& name);
/// "epsilon", "sample".
std::string to_string(DdpmPrediction prediction);
/// Throws InvalidArgument naming the value and the valid names.
DdpmPrediction parse_ddpm_prediction(const std::string& name);
/// "key_points", "image".
std::string to_string(ObservationKind kind);
/// Throws InvalidArgument naming the value and the valid names.
ObservationKind parse_observation(const std::string& name);
/// What an image policy's encoder hands the MLP (image_flow_head.hpp): its last map flattened
/// (flatten), or one soft-argmax point per channel of it (spatial_softmax, spatial_softmax.hpp).
enum class ImageFeatures { flatten, spatial_softmax };
/// "flatten", "spatial_softmax".
std::string to_string(ImageFeatures features);
/// Throws InvalidArgument naming the value and the valid names.
ImageFeatures parse_image_features(const std::string& name);

/// One layer of PolicyConfig::encoder: a 3 x 3 convolution with `channels` filters and `stride`.
struct EncoderLayerSetting {
  int channels = 0;
  int stride = 2;
};
/// PolicyConfig::encoder's layers: comma-separated out_channels, each of stride 2 unless it ends
/// in "/1" ("8,16/1" -> {8, stride 2}, {16, stride 1}). Throws InvalidArgument naming the bad
/// entry unless it is 1 to 6 layers of 1..256 channels.
std::vector<EncoderLayerSetting> parse_encoder(const std::string& text);

/// The tasks a model can be trained for: the 2D peg-in-hole ("peg2d", Sec. 4.2) and the 3D blade
/// insertion ("insert3d", Table 2's analogue). Observations of the two differ in shape and
/// meaning, so a model only runs on the task it was trained for.
inline constexpr const char* kTaskPeg2d = "peg2d";
inline constexpr const char* kTaskInsert3d = "insert3d";

struct PolicyConfig {
  /// The task the model was trained on. to_text writes the line only for a task other than
  /// peg2d, so 2D model files (and the table1 cell hashes over this text) are unchanged, and a
  /// file without it (every model written before the 3D task) reads as peg2d.
  std::string task = kTaskPeg2d;
  HeadKind head = HeadKind::flow;
  std::string representation = "hand_centric";
  int chunk_length = 16;  ///< K
  /// H = 0: with past poses the observation carries the hand's velocity, which the policy copies
  /// past the hole's axis (6 -> 32 of 50 insertions on the tuning seeds; docs/SIM.md).
  int history_length = 0;
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
  // Training. The defaults are the best configuration measured on the peg-in-hole task
  // (docs/EXPERIMENTS.md); `handcentric train` only overrides them.
  /// Adam steps; 0 = the automatic budget, training_budget(samples) (trainer.hpp), which grows
  /// with the number of training samples. The trained model stores the steps it ran.
  int steps = 0;
  int batch_size = 256;
  /// The peak: at every step (constant) or at the first (cosine). 2e-3 beat 1e-3 under the
  /// cosine schedule (40 against 35 of 50 tuning rollouts, docs/SIM.md).
  double learning_rate = 2e-3;
  /// cosine by default: on 100 peg-in-hole demos (H = 0, 60000 steps) flow / hand_centric
  /// succeeds in 40 of 50 tuning rollouts with it and 13 of 50 with a constant rate (docs/SIM.md).
  LearningRateSchedule lr_schedule = LearningRateSchedule::cosine;
  double weight_decay = 0.0;   ///< decoupled (AdamW)
  double gradient_clip = 1.0;  ///< global L2 norm; 0 disables
  /// Keep the exponential moving average of the weights (weight_average.hpp) and put it in the
  /// model: 0 = off (the default), 0.999 is usual.
  double ema_decay = 0.0;
  // Sampling and heads.
  /// Scale of the flow sampler's starting noise (flow and c8flow): 1 draws a chunk from the
  /// learned distribution; 0 starts every Euler integration from the prior's mode, the single
  /// most likely chunk that eq. (6) asks for (deterministic given the observation). 0 because
  /// a random draw spreads the chunk by more than the 0.05 cm per side the hole allows: 0.60
  /// -> 0.92 success on 100 tuning rollouts (docs/EXPERIMENTS.md).
  double noise_scale = 0.0;
  /// Poses of each K-pose chunk the robot executes before it replans (Sec. 4.2's rollouts).
  /// 4: replanning twice as often corrects the approach to the hole before it touches a wall
  /// (0.92 -> 0.97 with noise_scale 0; docs/EXPERIMENTS.md).
  int execute = 4;
  int euler_steps = 10;        ///< rectified flow, eq. (5)
  int ddpm_train_steps = 100;  ///< DDPM diffusion steps
  int ddim_steps = 10;         ///< DDIM sampling steps
  /// Head ddpm only. sample by default: on the tuning seeds hand-centric DDPM inserts 0.87 of
  /// the time at 40 demos with it and 0.00 with epsilon, whose first DDIM step divides the
  /// network's error by sqrt(abar) ~ 5e-4 (docs/EXPERIMENTS.md, "Fig. 5's heads").
  /// to_text writes it for head ddpm only, and a ddpm file without it (every one written before
  /// this setting) reads as epsilon, what it was trained with. c8ddpm always predicts epsilon
  /// (c8_planar.hpp).
  DdpmPrediction ddpm_prediction = DdpmPrediction::sample;
  int cvae_latent = 16;
  /// The KL term's weight in the CVAE loss (cvae_loss.hpp). 10, as ACT (Zhao et al. 2023): the
  /// sampler decodes the prior's mean z = 0, which a weak KL term leaves far from the codes the
  /// decoder was trained on. On the tuning seeds hand-centric CVAE at 40 demos inserts 0.75 of
  /// the time with 10, 0.69 with 1, 0.67 with 100 and 0.03 with 0.01 (docs/EXPERIMENTS.md).
  double cvae_kl_weight = 10.0;
  /// The point C8 rotates about (world x, y; the task's cm) for heads c8ddpm, c8flow_planar and
  /// c8ddpm_avg (c8_planar.hpp).
  /// Stored only for that head, so other heads' configs (and Table 1 hashes) are unchanged.
  double c8_centre_x = 0.0;
  double c8_centre_y = 0.0;
  /// key_points (the default) or image. The image fields below are written for image models
  /// only, so key-point model files (and Table 1's hashes) are unchanged and a file without
  /// them reads as key_points. Image models: head flow only.
  ObservationKind observation = ObservationKind::key_points;
  /// The camera's image, set by the trainer from the ImageSource: per camera 1 channel (depth), 3
  /// (the surface normal's x and y, then depth) or 4 (red, green, blue, depth), height x width
  /// pixels.
  int image_channels = 0;
  int image_height = 0;
  int image_width = 0;
  /// The encoder's layers: their out_channels, comma-separated, each a 3 x 3 convolution of
  /// stride 2 (or 1, written "16/1") and padding 1 (conv_encoder.hpp). Three layers of 8, 16 and 16
  /// turn a 32 x 24 depth image into 16 x 4 x 3 = 192 features in ~3.6k weights: the MLP's first
  /// layer then costs about what the key points' does (768 features after two layers would
  /// quadruple it).
  std::string encoder = "8,16,16";
  /// What the MLP gets from the encoder's last map. An image model file without the key (every
  /// one written before it existed) reads as this default, flatten, what it was trained with: the
  /// default stays (a task's image defaults live with the task, experiments/insert3d_image.hpp).
  ImageFeatures image_features = ImageFeatures::flatten;
  /// The hand camera's horizontal field of view (deg), for the task to rebuild the camera the
  /// model was trained with (a model file holds no camera). A file without the key reads as this
  /// default, 70, the only camera there was; it stays for that reason.
  double image_fov_deg = 70.0;
  /// The hand cameras whose images are stacked along the channels (image_channels counts them
  /// all: per camera 1, 3 or 4): 1, or 2 (the task's camera and its mirror about the blade). A
  /// file without the key reads as 1, the only rig there was.
  int image_cameras = 1;

  /// The image's shape (image_channels, image_height, image_width).
  int image_size() const { return image_channels * image_height * image_width; }
  /// Rows of the observation vector the representation encodes: observation_dimension less the
  /// image for an image model.
  int proprio_dimension() const {
    return observation == ObservationKind::image ? observation_dimension - image_size()
                                                 : observation_dimension;
  }

  /// Throws InvalidArgument naming the first out-of-range field and its valid range.
  void validate() const;
  std::string to_text() const;
  /// Parses to_text() output; throws InvalidArgument for an unknown key or a bad value. Keys
  /// left out keep their defaults, except a ddpm config without ddpm_prediction, which reads as
  /// epsilon (what a model file written before the setting was trained with).
  static PolicyConfig from_text(const std::string& text);
};

}  // namespace handcentric::policy
