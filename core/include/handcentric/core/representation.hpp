#pragma once
// Representation: how actions and observations become the Euclidean vectors a network sees.
//
// Vector layouts (all built-ins):
//   actions     : for k = 1..K, [translation (3), rotation vector (3)]          -> 6K numbers
//   observation : for h = 0..H, [translation (3), rotation vector (3)] of T_{-h},
//                 then the eye-in-hand points (3 each), then the world points (3 each)
// A world point is a third-person view (a fixed camera's point, in the world frame). absolute,
// relative and relative_diff copy it raw, so their observation is not invariant with one
// (Theorem 1 assumes eye-in-hand views); hand_centric expresses it in the hand frame,
// T_0^{-1} q, which no global transform changes.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/scene.hpp"

namespace handcentric {

class Representation {
 public:
  virtual ~Representation() = default;

  /// The name used on the command line and in reports, e.g. "hand_centric".
  virtual std::string name() const = 0;

  /// The action chunk as a vector. Throws InvalidScene for an invalid scene.
  virtual Eigen::VectorXd encode_actions(const Scene& scene) const = 0;

  /// The observation (proprioception history, eye-in-hand points, world points) as a vector.
  /// Reads no action: the chunk may be empty. Throws InvalidScene for an invalid observation.
  virtual Eigen::VectorXd encode_observation(const Scene& scene) const = 0;

  /// Whether decode_actions() is available (a plug-in representation may only encode).
  virtual bool can_decode() const { return true; }

  /// The world-frame chunk T_{1..K} that `actions` encodes, given the hand now (T_0).
  /// Throws InvalidArgument for a length that is not a positive multiple of 6 or a
  /// non-finite entry.
  virtual std::vector<RigidTransform> decode_actions(const Eigen::VectorXd& actions,
                                                     const RigidTransform& world_T_hand0) const = 0;

  /// decode_actions with the whole observation at hand (history, points, extra poses, scalars),
  /// for a decoder that reads more than T_0 (a plug-in's may). By default: T_0 only.
  virtual std::vector<RigidTransform> decode_in_scene(const Eigen::VectorXd& actions,
                                                      const Scene& observation) const {
    return decode_actions(actions, observation.world_T_hand0());
  }
};

}  // namespace handcentric
