#include "handcentric/policy/c8_planar.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"

namespace handcentric::policy::c8 {
namespace {

// A rotation vector off the z axis by more than this is not a planar pose. Rotation vectors of
// planar poses come out of so3::log with exact zeros there; 1e-6 leaves room for round-off.
constexpr double kPlanarTolerance = 1e-6;

void check_size(Eigen::Index size, int expected, const char* what) {
  if (size != expected) {
    throw InvalidArgument(
        std::string("C8 planar encoding: ") + what + " of length " + std::to_string(size) +
        ", expected " + std::to_string(expected) +
        " for the layout (H + 1 or K pose blocks, then the points): train with the "
        "absolute representation");
  }
}

// cos and sin of k * 45 deg, exact at multiples of 90 deg, so that 4 quarter turns are the
// identity to the last bit. A table: the training step moves every minibatch column.
const Eigen::Vector2d& cos_sin(int k) {
  static const std::array<Eigen::Vector2d, 8> table = [] {
    std::array<Eigen::Vector2d, 8> out;
    for (int m = 0; m < 8; ++m) {
      const double angle = m * std::numbers::pi / 4.0;
      out[static_cast<std::size_t>(m)] =
          m % 2 == 0 ? Eigen::Vector2d(std::round(std::cos(angle)), std::round(std::sin(angle)))
                     : Eigen::Vector2d(std::cos(angle), std::sin(angle));
    }
    return out;
  }();
  return table[static_cast<std::size_t>(((k % 8) + 8) % 8)];
}

Eigen::Vector2d rotate(const Eigen::Vector2d& cs, const Eigen::Vector2d& v) {
  return {cs.x() * v.x() - cs.y() * v.y(), cs.y() * v.x() + cs.x() * v.y()};
}

}  // namespace

Layout action_layout(const PolicyConfig& config) {
  return Layout{config.chunk_length, 0, 0};
}

Layout observation_layout(const PolicyConfig& config) {
  return Layout{config.history_length + 1, config.hand_points, config.world_points};
}

Eigen::VectorXd encode_planar(const Eigen::VectorXd& absolute, const Layout& layout) {
  check_size(absolute.size(), layout.absolute_size(), "an absolute vector");
  Eigen::VectorXd out(layout.planar_size());
  for (int i = 0; i < layout.poses; ++i) {
    const auto pose = absolute.segment<6>(6 * i);
    if (std::abs(pose[3]) > kPlanarTolerance || std::abs(pose[4]) > kPlanarTolerance) {
      throw InvalidArgument(
          "C8 planar encoding: pose " + std::to_string(i) + " has the rotation vector (" +
          format_number(pose[3]) + ", " + format_number(pose[4]) + ", " + format_number(pose[5]) +
          "), not a rotation about z: head c8ddpm is for planar (2D task) poses; use "
          "--head ddpm or flow for 3D ones");
    }
    out.segment<3>(kPlanarPoseSize * i) = pose.head<3>();
    out[kPlanarPoseSize * i + 3] = std::cos(pose[5]);
    out[kPlanarPoseSize * i + 4] = std::sin(pose[5]);
  }
  out.tail(absolute.size() - 6 * layout.poses) = absolute.tail(absolute.size() - 6 * layout.poses);
  return out;
}

Eigen::VectorXd decode_planar(const Eigen::VectorXd& planar, const Layout& layout) {
  check_size(planar.size(), layout.planar_size(), "a planar vector");
  Eigen::VectorXd out(layout.absolute_size());
  for (int i = 0; i < layout.poses; ++i) {
    const auto pose = planar.segment<kPlanarPoseSize>(kPlanarPoseSize * i);
    out.segment<3>(6 * i) = pose.head<3>();
    out.segment<3>(6 * i + 3) = Eigen::Vector3d(0.0, 0.0, std::atan2(pose[4], pose[3]));
  }
  const Eigen::Index points = planar.size() - kPlanarPoseSize * layout.poses;
  out.tail(points) = planar.tail(points);
  return out;
}

namespace {

// g_k on a planar vector (the header's formula), each moved number rounded to `Scalar` as it is
// written into `out`, which holds `planar` (rounded alike) on entry. The one copy of the group's
// arithmetic: act_planar and act_planar_float round the same doubles, so the float32 training
// columns are act_planar's, rounded.
template <typename Scalar>
void move_planar(int k, const Eigen::Vector2d& centre,
                 const Eigen::Ref<const Eigen::VectorXd>& planar, const Layout& layout,
                 Eigen::Ref<Eigen::Matrix<Scalar, Eigen::Dynamic, 1>> out) {
  // The identity exactly: c + (x - c) need not round back to x.
  if (k % 8 == 0) return;
  const Eigen::Vector2d cs = cos_sin(k);
  for (int i = 0; i < layout.poses; ++i) {
    const Eigen::Index at = kPlanarPoseSize * i;
    out.template segment<2>(at) =
        (centre + rotate(cs, planar.segment<2>(at) - centre)).template cast<Scalar>();
    // The heading.
    out.template segment<2>(at + 3) = rotate(cs, planar.segment<2>(at + 3)).template cast<Scalar>();
  }
  // Eye-in-hand points stay; world points move like positions.
  const Eigen::Index world = kPlanarPoseSize * layout.poses + 3 * layout.hand_points;
  for (int i = 0; i < layout.world_points; ++i) {
    const Eigen::Index at = world + 3 * i;
    out.template segment<2>(at) =
        (centre + rotate(cs, planar.segment<2>(at) - centre)).template cast<Scalar>();
  }
}

}  // namespace

Eigen::VectorXd act_planar(int k, const Eigen::Vector2d& centre, const Eigen::VectorXd& planar,
                           const Layout& layout) {
  check_size(planar.size(), layout.planar_size(), "a planar vector");
  Eigen::VectorXd out = planar;
  move_planar<double>(k, centre, planar, layout, out);
  return out;
}

void act_planar_float(int k, const Eigen::Vector2d& centre,
                      const Eigen::Ref<const Eigen::VectorXd>& planar, const Layout& layout,
                      Eigen::Ref<Eigen::VectorXf> out) {
  check_size(planar.size(), layout.planar_size(), "a planar vector");
  check_size(out.size(), layout.planar_size(), "the output vector");
  out = planar.cast<float>();
  move_planar<float>(k, centre, planar, layout, out);
}

Eigen::MatrixXd orbit(const Eigen::MatrixXd& planar, const Eigen::Vector2d& centre,
                      const Layout& layout) {
  Eigen::MatrixXd out(planar.rows(), 8 * planar.cols());
  for (Eigen::Index j = 0; j < planar.cols(); ++j) {
    for (int k = 0; k < 8; ++k) out.col(8 * j + k) = act_planar(k, centre, planar.col(j), layout);
  }
  return out;
}

Eigen::Vector2d centre_of(const PolicyConfig& config) {
  return {config.c8_centre_x, config.c8_centre_y};
}

int augmentation_copies(HeadKind head) {
  return is_c8_planar(head) ? 8 : 1;
}

PolicyConfig inner_config(const PolicyConfig& config) {
  check_size(config.action_dimension, action_layout(config).absolute_size(),
             "the action dimension");
  check_size(config.observation_dimension, observation_layout(config).absolute_size(),
             "the observation dimension");
  PolicyConfig inner = config;
  inner.head = trained_as(config.head) == HeadKind::c8flow_planar ? HeadKind::flow : HeadKind::ddpm;
  // Epsilon, as [7] (on Diffusion Policy's default). On the tuning seeds c8_base scored 0.00 at
  // 40 demos with either prediction (docs/EXPERIMENTS.md), so faithfulness to [7] decides.
  inner.ddpm_prediction = DdpmPrediction::epsilon;
  inner.action_dimension = action_layout(config).planar_size();
  inner.observation_dimension = observation_layout(config).planar_size();
  return inner;
}

}  // namespace handcentric::policy::c8
