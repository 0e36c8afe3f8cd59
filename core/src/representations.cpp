#include "handcentric/core/representations.hpp"

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/core/so3.hpp"

namespace handcentric {
namespace {

constexpr Eigen::Index kPoseSize = 6;  // [translation (3), rotation vector (3)]

void put_pose(Eigen::VectorXd& out, Eigen::Index slot, const Eigen::Vector3d& translation,
              const Eigen::Vector3d& rotation_vector) {
  out.segment<3>(kPoseSize * slot) = translation;
  out.segment<3>(kPoseSize * slot + 3) = rotation_vector;
}

// The observation's point block from `offset` on: eye-in-hand points as they are, then world
// points mapped by `frame_T_world` (the identity: copied raw; T_0^{-1}: in the hand frame).
void put_points(Eigen::VectorXd& out, Eigen::Index offset, const Scene& scene,
                const RigidTransform& frame_T_world) {
  for (const Eigen::Vector3d& point_hand0 : scene.hand_points) {
    out.segment<3>(offset) = point_hand0;
    offset += 3;
  }
  for (const Eigen::Vector3d& point_world : scene.world_points) {
    out.segment<3>(offset) = frame_T_world * point_world;
    offset += 3;
  }
}

Eigen::VectorXd observation_buffer(const Scene& scene) {
  const Eigen::Index poses = static_cast<Eigen::Index>(scene.world_T_hand_history.size());
  const Eigen::Index points =
      static_cast<Eigen::Index>(scene.hand_points.size() + scene.world_points.size());
  return Eigen::VectorXd(kPoseSize * poses + 3 * points);
}

// World-frame proprioception o_{-h} = T_{-h} (Sec. 2.1), used by absolute, relative, relative_diff.
Eigen::VectorXd world_observation(const Scene& scene) {
  scene.validate_observation();
  Eigen::VectorXd out = observation_buffer(scene);
  Eigen::Index slot = 0;
  for (const RigidTransform& world_T_hand : scene.world_T_hand_history) {
    put_pose(out, slot++, world_T_hand.translation(), world_T_hand.rotation().log());
  }
  put_points(out, kPoseSize * slot, scene, RigidTransform::identity());  // third-person: raw
  return out;
}

// Checks a vector to decode and returns K.
Eigen::Index chunk_length_of(const Eigen::VectorXd& actions, const std::string& representation) {
  if (actions.size() == 0 || actions.size() % kPoseSize != 0) {
    throw InvalidArgument(representation + " action vector has length " +
                          std::to_string(actions.size()) +
                          "; it must be 6K (translation and rotation vector per action), K >= 1");
  }
  if (!actions.allFinite()) {
    throw InvalidArgument(representation +
                          " action vector has a non-finite entry: " + format_matrix(actions));
  }
  return actions.size() / kPoseSize;
}

}  // namespace

// ---- absolute: a_k = (p_k, r(R_k)), App. A.1 eqs. (10), (12) ----

Eigen::VectorXd AbsoluteRepresentation::encode_actions(const Scene& scene) const {
  scene.validate();
  Eigen::VectorXd out(kPoseSize * scene.chunk_length());
  Eigen::Index slot = 0;
  for (const RigidTransform& world_T_handk : scene.world_T_hand_chunk) {
    put_pose(out, slot++, world_T_handk.translation(), world_T_handk.rotation().log());
  }
  return out;
}

Eigen::VectorXd AbsoluteRepresentation::encode_observation(const Scene& scene) const {
  return world_observation(scene);
}

std::vector<RigidTransform> AbsoluteRepresentation::decode_actions(
    const Eigen::VectorXd& actions, const RigidTransform& /*world_T_hand0*/) const {
  const Eigen::Index K = chunk_length_of(actions, name());
  std::vector<RigidTransform> chunk;
  chunk.reserve(static_cast<std::size_t>(K));
  for (Eigen::Index k = 0; k < K; ++k) {
    chunk.push_back(RigidTransform::unchecked(so3::exp(actions.segment<3>(kPoseSize * k + 3)),
                                              actions.segment<3>(kPoseSize * k)));
  }
  return chunk;
}

// ---- relative (Sec. 2.1): (p_k - p_0, r(R_0^T R_k)) ----

Eigen::VectorXd RelativeRepresentation::encode_actions(const Scene& scene) const {
  scene.validate();
  const RigidTransform& world_T_hand0 = scene.world_T_hand0();
  Eigen::VectorXd out(kPoseSize * scene.chunk_length());
  Eigen::Index slot = 0;
  for (const RigidTransform& world_T_handk : scene.world_T_hand_chunk) {
    put_pose(out, slot++, world_T_handk.translation() - world_T_hand0.translation(),
             world_T_hand0.rotation().inverse_compose(world_T_handk.rotation()).log());
  }
  return out;
}

Eigen::VectorXd RelativeRepresentation::encode_observation(const Scene& scene) const {
  return world_observation(scene);
}

std::vector<RigidTransform> RelativeRepresentation::decode_actions(
    const Eigen::VectorXd& actions, const RigidTransform& world_T_hand0) const {
  const Eigen::Index K = chunk_length_of(actions, name());
  const Eigen::Matrix3d& R0 = world_T_hand0.rotation().matrix();
  std::vector<RigidTransform> chunk;
  chunk.reserve(static_cast<std::size_t>(K));
  for (Eigen::Index k = 0; k < K; ++k) {
    chunk.push_back(
        RigidTransform::unchecked(R0 * so3::exp(actions.segment<3>(kPoseSize * k + 3)),
                                  world_T_hand0.translation() + actions.segment<3>(kPoseSize * k)));
  }
  return chunk;
}

// ---- relative_diff (App. A.2, eq. 14): (p_k - p_0, r(R_k) - r(R_0)) ----

Eigen::VectorXd RelativeDiffRepresentation::encode_actions(const Scene& scene) const {
  scene.validate();
  const RigidTransform& world_T_hand0 = scene.world_T_hand0();
  const Eigen::Vector3d r0 = world_T_hand0.rotation().log();
  Eigen::VectorXd out(kPoseSize * scene.chunk_length());
  Eigen::Index slot = 0;
  for (const RigidTransform& world_T_handk : scene.world_T_hand_chunk) {
    put_pose(out, slot++, world_T_handk.translation() - world_T_hand0.translation(),
             world_T_handk.rotation().log() - r0);
  }
  return out;
}

Eigen::VectorXd RelativeDiffRepresentation::encode_observation(const Scene& scene) const {
  return world_observation(scene);
}

std::vector<RigidTransform> RelativeDiffRepresentation::decode_actions(
    const Eigen::VectorXd& actions, const RigidTransform& world_T_hand0) const {
  const Eigen::Index K = chunk_length_of(actions, name());
  const Eigen::Vector3d r0 = world_T_hand0.rotation().log();
  std::vector<RigidTransform> chunk;
  chunk.reserve(static_cast<std::size_t>(K));
  for (Eigen::Index k = 0; k < K; ++k) {
    chunk.push_back(
        RigidTransform::unchecked(so3::exp(r0 + actions.segment<3>(kPoseSize * k + 3)),
                                  world_T_hand0.translation() + actions.segment<3>(kPoseSize * k)));
  }
  return chunk;
}

// ---- hand_centric, eqs. (1)-(3): hand0_T_handk = T_0^{-1} T_k ----

Eigen::VectorXd HandCentricRepresentation::encode_actions(const Scene& scene) const {
  scene.validate();
  const RigidTransform& world_T_hand0 = scene.world_T_hand0();
  Eigen::VectorXd out(kPoseSize * scene.chunk_length());
  Eigen::Index slot = 0;
  for (const RigidTransform& world_T_handk : scene.world_T_hand_chunk) {
    const RigidTransform hand0_T_handk = world_T_hand0.inverse_compose(world_T_handk);  // eq. (2)
    put_pose(out, slot++, hand0_T_handk.translation(), hand0_T_handk.rotation().log());
  }
  return out;
}

Eigen::VectorXd HandCentricRepresentation::encode_observation(const Scene& scene) const {
  scene.validate_observation();
  const RigidTransform& world_T_hand0 = scene.world_T_hand0();
  Eigen::VectorXd out = observation_buffer(scene);
  Eigen::Index slot = 0;
  for (const RigidTransform& world_T_hand : scene.world_T_hand_history) {
    const RigidTransform hand0_T_hand = world_T_hand0.inverse_compose(world_T_hand);  // eq. (3)
    put_pose(out, slot++, hand0_T_hand.translation(), hand0_T_hand.rotation().log());
  }
  // A third-person point q seen in the hand frame, T_0^{-1} q: (g T_0)^{-1} (g q) = T_0^{-1} q,
  // so a calibrated fixed camera keeps the observation invariant, as eq. (9) does for poses.
  put_points(out, kPoseSize * slot, scene, world_T_hand0.inverse());
  return out;
}

std::vector<RigidTransform> HandCentricRepresentation::decode_actions(
    const Eigen::VectorXd& actions, const RigidTransform& world_T_hand0) const {
  const Eigen::Index K = chunk_length_of(actions, name());
  std::vector<RigidTransform> chunk;
  chunk.reserve(static_cast<std::size_t>(K));
  for (Eigen::Index k = 0; k < K; ++k) {
    // Inverse of eq. (1): T_k = T_0 hand0_T_handk (Theorem 1's outer action).
    chunk.push_back(world_T_hand0 *
                    RigidTransform::unchecked(so3::exp(actions.segment<3>(kPoseSize * k + 3)),
                                              actions.segment<3>(kPoseSize * k)));
  }
  return chunk;
}

// ---- registry ----

std::vector<std::string> builtin_representation_names() {
  return {"absolute", "relative", "relative_diff", "hand_centric"};
}

std::unique_ptr<Representation> make_representation(const std::string& name) {
  if (name == "absolute") return std::make_unique<AbsoluteRepresentation>();
  if (name == "relative") return std::make_unique<RelativeRepresentation>();
  if (name == "relative_diff") return std::make_unique<RelativeDiffRepresentation>();
  if (name == "hand_centric") return std::make_unique<HandCentricRepresentation>();
  throw InvalidArgument("unknown representation '" + name +
                        "'; choose one of absolute, relative, relative_diff, hand_centric");
}

}  // namespace handcentric
