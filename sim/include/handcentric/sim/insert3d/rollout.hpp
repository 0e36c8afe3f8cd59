#pragma once
// Closed-loop chunked rollouts of any ChunkPolicy on the 3D blade insertion, and the observation
// a policy sees: the hand's poses T_0, ..., T_-H (the start repeated before it) and the slot
// opening's four corners in the hand frame (eye-in-hand, "Guaranteed SE(3)-Equivariant Control
// via Hand-Centric Behavior Cloning", Sec. 3.2).
//
// Each replan: observe, act (noise seed splitmix64(seed, replan)), execute the first `execute`
// poses of the chunk. A command beyond kMaxStepCm or kMaxStepDeg from the current pose is clipped
// to the limits along interpolate() and counted. Every step's motion is checked continuously in
// the slot frame; the first contact ends the rollout as `collision`, the tip kSuccessDepth deep
// inside the slot ends it as `success`, running out of replans is `timeout`, and a non-finite
// command (or NonFiniteAction from the policy) is `invalid`. Clipping, interpolation and the
// checks depend only on poses relative to each other and to the slot, so for an equivariant
// policy the rollout of g * scene is g times the rollout of the scene (tests/sim).
#include <cstdint>
#include <string>
#include <vector>

#include "handcentric/core/chunk_policy.hpp"
#include "handcentric/core/scene.hpp"
#include "handcentric/sim/insert3d/collision.hpp"
#include "handcentric/sim/insert3d/scenes.hpp"
#include "handcentric/sim/outcome.hpp"

namespace handcentric::sim::insert3d {

struct RolloutOptions {
  int history = 2;       ///< H, past poses in the observation
  int execute = 8;       ///< poses executed per chunk
  int max_replans = 25;  ///< at most 200 steps with execute = 8

  /// Throws InvalidArgument naming the value: history < 0, execute < 1, max_replans < 1.
  void validate() const;
};

struct Rollout {
  Outcome outcome = Outcome::timeout;
  std::vector<RigidTransform> world_T_hand;  ///< every pose reached; [0] = start
  int clipped = 0;                           ///< commands clipped to the step limits
};

/// The observation at the last pose of world_T_hand (non-empty): history and the four corners.
Scene observe(const TaskScene& scene, const std::vector<RigidTransform>& world_T_hand, int history,
              const BladeSlotGeometry& geometry = BladeSlotGeometry());

/// One closed-loop rollout. Throws InvalidArgument for bad options or an empty chunk (naming the
/// policy).
Rollout rollout(const ChunkPolicy& policy, const TaskScene& scene, std::uint64_t seed,
                const CollisionChecker& checker, const RolloutOptions& options = RolloutOptions());

/// The slot's pose in the hand frame read from the four opening corners in the hand frame
/// (BladeSlotGeometry::opening_corners' order): what an eye-in-hand policy knows of the slot.
RigidTransform hand_T_slot_from_corners(const std::vector<Eigen::Vector3d>& hand_corners);

/// The expert in closed loop: reads the slot from the corners, plans from the current pose
/// without a random via point (or, once lined up with the axis, straight down it), returns K
/// poses.
class ClosedLoopExpert final : public ChunkPolicy {
 public:
  explicit ClosedLoopExpert(int chunk_length = 16,
                            const BladeSlotGeometry& geometry = BladeSlotGeometry());
  std::string name() const override { return "insert3d-expert"; }
  std::vector<RigidTransform> act(const Scene& observation,
                                  std::uint64_t noise_seed) const override;

 private:
  int chunk_length_;
  CollisionChecker checker_;
};

}  // namespace handcentric::sim::insert3d
