#pragma once
// Scene: what a policy sees and does at one control step, in the world frame.
//
//   world_T_hand_history[h] = T_{-h}, h = 0..H   (index 0 is the hand now, T_0)
//   world_T_hand_chunk[k-1] = T_k,    k = 1..K   (the action chunk a_{1:K})
//   world_points            third-person view: points in the world frame
//   hand_points             eye-in-hand view: points in the current hand frame (Sec. 3.2)
//   extra_poses             other named world-frame poses (the episode's start pose, a second
//                           arm's hand): they move with the scene
//   scalars                 named numbers no transform changes (a gripper's width)
//   held                    named arrays no transform changes (a dataset's eye-in-hand image)
//
// A global rigid transform g acts as in Sec. 2.2: g * scene moves every pose (T -> g T) and
// every world point (x -> g x), and leaves the eye-in-hand points, the scalars and the held
// arrays alone, because
// the camera, the hand and the objects move together (the proposition behind Lemma 2).
#include <Eigen/Core>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "handcentric/core/held_array.hpp"
#include "handcentric/core/rigid_transform.hpp"

namespace handcentric {

struct Scene {
  std::vector<RigidTransform> world_T_hand_history;  ///< [h] = T_{-h}; [0] = T_0
  std::vector<RigidTransform> world_T_hand_chunk;    ///< [k-1] = T_k
  std::vector<Eigen::Vector3d> world_points;         ///< world frame
  std::vector<Eigen::Vector3d> hand_points;          ///< frame of the hand at T_0
  /// Named world-frame poses besides the hand's (world_T_name), in a fixed order.
  std::vector<std::pair<std::string, RigidTransform>> extra_poses;
  /// Named numbers that a global transform leaves alone, in a fixed order.
  std::vector<std::pair<std::string, double>> scalars;
  /// Named arrays that a global transform leaves alone, in a fixed order (shared, read-only).
  std::vector<std::pair<std::string, std::shared_ptr<const HeldArray>>> held;

  /// T_0, the hand now. Precondition: the history is not empty (see validate()).
  const RigidTransform& world_T_hand0() const { return world_T_hand_history.front(); }

  /// H, the number of past poses besides T_0.
  int history_length() const { return static_cast<int>(world_T_hand_history.size()) - 1; }

  /// K, the chunk length.
  int chunk_length() const { return static_cast<int>(world_T_hand_chunk.size()); }

  /// Throws InvalidScene naming the problem: empty history, empty chunk, non-finite point.
  void validate() const;

  /// What a policy may read (history, points, extra poses, scalars; the chunk is not looked
  /// at): throws InvalidScene for an empty history, a non-finite point or scalar.
  void validate_observation() const;
};

/// g * scene (Sec. 2.2's "T~ o"): poses (extra ones too) and world points move, eye-in-hand
/// points, scalars and held arrays do not.
Scene operator*(const RigidTransform& g, const Scene& scene);

}  // namespace handcentric
