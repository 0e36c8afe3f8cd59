#pragma once
// The planar encoding of the C8 baseline (head c8ddpm), the stand-in for the 2D variant of
// Equivariant Diffusion Policy [7]: positions and (cos, sin) headings that rotate with C8 about
// a fixed point c, eye-in-hand features that the group leaves alone.
//
// An absolute vector (representation.hpp) is a list of pose blocks [p (3), r (3)] followed by
// points (3 each). The 2D task's poses are SE(2) embedded in SE(3): r = (0, 0, theta). Each pose
// block becomes
//   [x, y, z, cos theta, sin theta]                                  (5 numbers)
// and C8's element k (rotation R_k about z by k * 45 deg through c = (c_x, c_y)) acts by
//   (x, y) -> c + R_k ((x, y) - c),   z -> z,   (cos, sin) -> R_k (cos, sin).
// The heading is a point on the circle, so there is no wrap at +-180 deg where the rotation
// vector jumps from (0, 0, pi) to (0, 0, -pi): a training pose at 170 deg and its C8 image at
// -145 deg stay continuous targets. World points (third-person views) move like positions;
// eye-in-hand points do not move (the camera turns with the hand, Sec. 3.2), so [7]'s
// "eye-in-hand features are invariant" holds by construction.
#include <Eigen/Core>

#include "handcentric/policy/config.hpp"

namespace handcentric::policy::c8 {

/// Numbers per pose block of the planar encoding: x, y, z, cos theta, sin theta.
inline constexpr int kPlanarPoseSize = 5;

/// Where the blocks of an absolute vector are: `poses` pose blocks (6 numbers each), then
/// `hand_points` eye-in-hand points, then `world_points` world points (3 numbers each).
struct Layout {
  int poses = 0;
  int hand_points = 0;
  int world_points = 0;

  int absolute_size() const { return 6 * poses + 3 * (hand_points + world_points); }
  int planar_size() const { return kPlanarPoseSize * poses + 3 * (hand_points + world_points); }
};

/// The layouts of a model's action (K poses) and observation (H + 1 poses, its points).
Layout action_layout(const PolicyConfig& config);
Layout observation_layout(const PolicyConfig& config);

/// The planar encoding of an absolute vector. Throws InvalidArgument for a length that does not
/// fit `layout` and for a pose whose rotation is not about z (|r_x| or |r_y| > 1e-6): the C8
/// baseline is for the 2D task.
Eigen::VectorXd encode_planar(const Eigen::VectorXd& absolute, const Layout& layout);

/// The absolute vector of a planar one: theta = atan2(sin, cos), so the network's (cos, sin)
/// need not have unit length. Throws InvalidArgument for a length that does not fit `layout`.
Eigen::VectorXd decode_planar(const Eigen::VectorXd& planar, const Layout& layout);

/// C8's element k (any integer; k and k + 8 are the same element) on a planar vector, rotating
/// about `centre` (world x, y). Throws InvalidArgument for a length that does not fit `layout`.
Eigen::VectorXd act_planar(int k, const Eigen::Vector2d& centre, const Eigen::VectorXd& planar,
                           const Layout& layout);

/// act_planar(k, centre, planar, layout).cast<float>(), written into `out` without allocating
/// (the planar C8 heads' training step, once per minibatch column). The same bits. Throws
/// InvalidArgument for a `planar` or `out` whose length does not fit `layout`.
void act_planar_float(int k, const Eigen::Vector2d& centre,
                      const Eigen::Ref<const Eigen::VectorXd>& planar, const Layout& layout,
                      Eigen::Ref<Eigen::VectorXf> out);

/// The 8x augmented data: column 8 j + k is g_k applied to column j of `planar` (each column
/// a planar vector of `layout`). A set that C8 maps onto itself, so the loss on it is the
/// orbit-averaged loss. Throws as act_planar.
Eigen::MatrixXd orbit(const Eigen::MatrixXd& planar, const Eigen::Vector2d& centre,
                      const Layout& layout);

/// The symmetry centre a c8ddpm config names (c8_centre_x, c8_centre_y).
Eigen::Vector2d centre_of(const PolicyConfig& config);

/// How many training samples each demo step stands for: 8 for the planar C8 heads, which
/// train on every sample's C8 orbit (the 8x augmented data), 1 for every other head. The automatic
/// budget counts the augmented data (training_budget(HeadKind, samples), trainer.hpp).
int augmentation_copies(HeadKind head);

/// The config of the network inside a c8ddpm or c8ddpm_avg (c8flow_planar, c8flow_avg) head: a
/// DDPM (flow) head on the planar dimensions, with every other setting of config (network,
/// training, noise_scale); the DDPM predicts epsilon whatever config.ddpm_prediction says. Throws
/// InvalidArgument if config's action or observation dimension does not fit its layout (an
/// observation with extra poses or scalars, which the C8 baseline does not transform).
PolicyConfig inner_config(const PolicyConfig& config);

}  // namespace handcentric::policy::c8
