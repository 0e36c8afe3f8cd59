#pragma once
// Planted faults for the props suite (besides tests/core/mutants.hpp): each check below is also
// run on one of these and must fail there.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/flow_target.hpp"
#include "handcentric/core/representations.hpp"
#include "../core/mutants.hpp"  // ForgetsRotationOnTranslation, UsesR0ForR0Transpose

namespace handcentric::test {

/// hand_centric whose decoder forgets R_0 on the translation: p_k = p_0 + t_k instead of
/// p_0 + R_0 t_k (the inverse of eq. 2 done wrong). Encodes correctly.
class DecoderForgetsR0 final : public Representation {
 public:
  std::string name() const override { return "mutant_decoder_forgets_R0"; }
  Eigen::VectorXd encode_actions(const Scene& scene) const override {
    return HandCentricRepresentation().encode_actions(scene);
  }
  Eigen::VectorXd encode_observation(const Scene& scene) const override {
    return HandCentricRepresentation().encode_observation(scene);
  }
  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd& a,
                                             const RigidTransform& world_T_hand0) const override {
    std::vector<RigidTransform> chunk =
        HandCentricRepresentation().decode_actions(a, world_T_hand0);
    for (std::size_t k = 0; k < chunk.size(); ++k) {
      const Eigen::Vector3d p =
          world_T_hand0.translation() + a.segment<3>(6 * static_cast<Eigen::Index>(k));
      chunk[k] = RigidTransform(chunk[k].rotation(), p);
    }
    return chunk;
  }
};

/// ActionFlow's target (eq. 29) with biased noise eps + m, m = (0, 0, 2) per action: the source
/// distribution N(m, I) is not rotation invariant, so neither is the target in distribution.
class BiasedNoiseActionFlow final : public FlowTarget {
 public:
  std::string name() const override { return "mutant_biased_noise_actionflow"; }
  Eigen::Index noise_dimension(const Scene& scene) const override {
    return inner_.noise_dimension(scene);
  }
  FlowSample operator()(const Scene& scene, const Eigen::VectorXd& eps, double t) const override {
    Eigen::VectorXd biased = eps;
    for (Eigen::Index k = 0; 3 * k + 2 < biased.size(); ++k) biased(3 * k + 2) += 2.0;
    return inner_(scene, biased, t);
  }

 private:
  ActionFlowTarget inner_;
};

/// The world-frame "delta" pose mode some public codebases ship: per k, p_k - p_{k-1} and
/// r(R_k R_{k-1}^T), with T_0 before T_1. Translation-invariant only, and injective given T_0.
class WorldDelta final : public Representation {
 public:
  std::string name() const override { return "world_delta"; }
  Eigen::VectorXd encode_actions(const Scene& scene) const override {
    scene.validate();
    Eigen::VectorXd out(6 * scene.chunk_length());
    RigidTransform previous = scene.world_T_hand0();
    for (int k = 0; k < scene.chunk_length(); ++k) {
      const RigidTransform& current = scene.world_T_hand_chunk[static_cast<std::size_t>(k)];
      out.segment<3>(6 * k) = current.translation() - previous.translation();
      out.segment<3>(6 * k + 3) =
          Rotation::from_matrix_unchecked(current.rotation().matrix() *
                                          previous.rotation().matrix().transpose())
              .log();
      previous = current;
    }
    return out;
  }
  Eigen::VectorXd encode_observation(const Scene& scene) const override {
    return HandCentricRepresentation().encode_observation(scene);
  }
  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd& a,
                                             const RigidTransform& world_T_hand0) const override {
    std::vector<RigidTransform> chunk;
    RigidTransform previous = world_T_hand0;
    for (Eigen::Index k = 0; 6 * k < a.size(); ++k) {
      previous = RigidTransform::unchecked(
          Rotation::exp(a.segment<3>(6 * k + 3)).matrix() * previous.rotation().matrix(),
          previous.translation() + a.segment<3>(6 * k));
      chunk.push_back(previous);
    }
    return chunk;
  }
};

/// hand_centric whose observation copies world points raw, as a fixed camera's point cloud in
/// the world frame: not invariant once a scene has world points (the third-person view).
class RawWorldPoints final : public Representation {
 public:
  std::string name() const override { return "mutant_raw_world_points"; }
  Eigen::VectorXd encode_actions(const Scene& scene) const override {
    return HandCentricRepresentation().encode_actions(scene);
  }
  Eigen::VectorXd encode_observation(const Scene& scene) const override {
    Eigen::VectorXd out = HandCentricRepresentation().encode_observation(scene);
    Eigen::Index offset = out.size() - 3 * static_cast<Eigen::Index>(scene.world_points.size());
    for (const Eigen::Vector3d& point_world : scene.world_points) {
      out.segment<3>(offset) = point_world;
      offset += 3;
    }
    return out;
  }
  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd& a,
                                             const RigidTransform& world_T_hand0) const override {
    return HandCentricRepresentation().decode_actions(a, world_T_hand0);
  }
};

/// Six zeros per action: invariant under every group, and useless (not injective).
class ConstantZeros final : public Representation {
 public:
  std::string name() const override { return "mutant_constant_zeros"; }
  Eigen::VectorXd encode_actions(const Scene& scene) const override {
    return Eigen::VectorXd::Zero(6 * scene.chunk_length());
  }
  Eigen::VectorXd encode_observation(const Scene& scene) const override {
    return HandCentricRepresentation().encode_observation(scene);
  }
  bool can_decode() const override { return false; }
  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd&,
                                             const RigidTransform&) const override {
    throw InvalidArgument("mutant_constant_zeros cannot decode");
  }
};

/// hand_centric translations only: drops every rotation (not injective), still SE(3)-invariant.
class TranslationsOnly final : public Representation {
 public:
  std::string name() const override { return "mutant_translations_only"; }
  Eigen::VectorXd encode_actions(const Scene& scene) const override {
    const Eigen::VectorXd full = HandCentricRepresentation().encode_actions(scene);
    Eigen::VectorXd out(full.size() / 2);
    for (Eigen::Index k = 0; 6 * k < full.size(); ++k)
      out.segment<3>(3 * k) = full.segment<3>(6 * k);
    return out;
  }
  Eigen::VectorXd encode_observation(const Scene& scene) const override {
    return HandCentricRepresentation().encode_observation(scene);
  }
  bool can_decode() const override { return false; }
  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd&,
                                             const RigidTransform&) const override {
    throw InvalidArgument("mutant_translations_only cannot decode");
  }
};

/// hand_centric computed in float32, as codebases that cast poses to float do: invariant up to
/// float32 rounding, not at 1e-9.
class Float32HandCentric final : public Representation {
 public:
  std::string name() const override { return "float32_hand_centric"; }
  Eigen::VectorXd encode_actions(const Scene& scene) const override {
    scene.validate();
    const Eigen::Matrix4f world_T_hand0 = scene.world_T_hand0().matrix().cast<float>();
    const Eigen::Matrix4f hand0_T_world = world_T_hand0.inverse();
    Eigen::VectorXd out(6 * scene.chunk_length());
    for (int k = 0; k < scene.chunk_length(); ++k) {
      const Eigen::Matrix4f hand0_T_handk =
          hand0_T_world *
          scene.world_T_hand_chunk[static_cast<std::size_t>(k)].matrix().cast<float>();
      out.segment<3>(6 * k) = hand0_T_handk.block<3, 1>(0, 3).cast<double>();
      // The rotation vector of the float32 matrix, taken in double: the rounding is float32's.
      const Eigen::AngleAxisd angle_axis(hand0_T_handk.block<3, 3>(0, 0).cast<double>());
      out.segment<3>(6 * k + 3) = angle_axis.angle() * angle_axis.axis();
    }
    return out;
  }
  Eigen::VectorXd encode_observation(const Scene& scene) const override {
    return HandCentricRepresentation().encode_observation(scene).cast<float>().cast<double>();
  }
  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd& a,
                                             const RigidTransform& world_T_hand0) const override {
    return HandCentricRepresentation().decode_actions(a, world_T_hand0);
  }
};

/// A 256-bin action tokenizer (RT-1 / OpenVLA style) on the hand-centric pose T_0^{-1} T_k: each
/// translation coordinate binned over [-1, 1] m, each rotation-vector coordinate over [-pi, pi],
/// clamped at the ends. Bins of 2 m / 256 = 7.8 mm and 2 pi / 256 = 0.025 rad: not injective
/// below them, and not at all beyond 1 m. Decodes to bin centres (which does not invert it).
class Tokenizer256 final : public Representation {
 public:
  static constexpr int kBins = 256;
  static constexpr double kPi = 3.141592653589793;
  std::string name() const override { return "tokenizer_256"; }
  Eigen::VectorXd encode_actions(const Scene& scene) const override {
    Eigen::VectorXd out = HandCentricRepresentation().encode_actions(scene);
    for (Eigen::Index i = 0; i < out.size(); ++i) out(i) = token(out(i), range(i));
    return out;
  }
  Eigen::VectorXd encode_observation(const Scene& scene) const override {
    return HandCentricRepresentation().encode_observation(scene);
  }
  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd& a,
                                             const RigidTransform& world_T_hand0) const override {
    Eigen::VectorXd centres(a.size());
    for (Eigen::Index i = 0; i < a.size(); ++i)
      centres(i) = -range(i) + (a(i) + 0.5) * 2.0 * range(i) / kBins;
    return HandCentricRepresentation().decode_actions(centres, world_T_hand0);
  }

 private:
  static double range(Eigen::Index i) { return i % 6 < 3 ? 1.0 : kPi; }
  static double token(double x, double range) {
    const double bin = std::floor((x + range) / (2.0 * range) * kBins);
    return std::clamp(bin, 0.0, kBins - 1.0);
  }
};

/// hand_centric discretized as a voxel policy does (PerAct style): the translation of
/// T_0^{-1} T_k in 1 cm voxels, its rotation as ZYX Euler angles in 5 degree bins (voxel and bin
/// indices). Not injective below 1 cm and 5 degrees. Decodes to voxel and bin centres.
class BinnedHandCentric final : public Representation {
 public:
  static constexpr double kVoxel = 0.01;
  static constexpr double kAngleBin = 5.0 * 3.141592653589793 / 180.0;
  std::string name() const override { return "binned_hand_centric"; }
  Eigen::VectorXd encode_actions(const Scene& scene) const override {
    scene.validate();
    Eigen::VectorXd out(6 * scene.chunk_length());
    for (int k = 0; k < scene.chunk_length(); ++k) {
      const RigidTransform hand0_T_handk = scene.world_T_hand0().inverse_compose(
          scene.world_T_hand_chunk[static_cast<std::size_t>(k)]);
      const Eigen::Matrix3d& R = hand0_T_handk.rotation().matrix();
      const Eigen::Vector3d euler(std::atan2(R(1, 0), R(0, 0)),
                                  std::atan2(-R(2, 0), std::hypot(R(2, 1), R(2, 2))),
                                  std::atan2(R(2, 1), R(2, 2)));  // yaw, pitch, roll
      out.segment<3>(6 * k) = (hand0_T_handk.translation() / kVoxel).array().floor().matrix();
      out.segment<3>(6 * k + 3) = (euler / kAngleBin).array().floor().matrix();
    }
    return out;
  }
  Eigen::VectorXd encode_observation(const Scene& scene) const override {
    return HandCentricRepresentation().encode_observation(scene);
  }
  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd& a,
                                             const RigidTransform& world_T_hand0) const override {
    std::vector<RigidTransform> chunk;
    for (Eigen::Index k = 0; 6 * k < a.size(); ++k) {
      const Eigen::Vector3d p = (a.segment<3>(6 * k).array() + 0.5).matrix() * kVoxel;
      const Eigen::Vector3d e = (a.segment<3>(6 * k + 3).array() + 0.5).matrix() * kAngleBin;
      const Eigen::Matrix3d R = (Eigen::AngleAxisd(e(0), Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(e(1), Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(e(2), Eigen::Vector3d::UnitX()))
                                    .toRotationMatrix();
      chunk.push_back(world_T_hand0 * RigidTransform::unchecked(R, p));
    }
    return chunk;
  }
};

/// A flow whose target is a - eps^3 (elementwise): not affine in eps, so in distribution it is
/// decided by the energy test.
class CubedNoiseFlow final : public FlowTarget {
 public:
  explicit CubedNoiseFlow(std::shared_ptr<const Representation> representation)
      : inner_(std::move(representation)) {}
  std::string name() const override { return "mutant_cubed_noise_flow"; }
  Eigen::Index noise_dimension(const Scene& scene) const override {
    return inner_.noise_dimension(scene);
  }
  FlowSample operator()(const Scene& scene, const Eigen::VectorXd& eps, double t) const override {
    FlowSample sample = inner_(scene, Eigen::VectorXd::Zero(eps.size()), t);
    sample.target -= eps.array().cube().matrix();
    return sample;
  }

 private:
  RectifiedFlow inner_;
};

}  // namespace handcentric::test
