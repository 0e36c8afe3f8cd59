#pragma once
// The expert of the 3D blade insertion: demonstrations for "Guaranteed SE(3)-Equivariant
// Control via Hand-Centric Behavior Cloning", planned in the slot's frame and kept only when the
// exact continuous collision check and the success test accept them.
//
// Everything is computed in the slot frame from slot_T_hand_start = world_T_slot^-1
// world_T_hand_start, and mapped back by world_T_slot, so the expert is equivariant by
// construction: expert(g * scene) = g * expert(scene) for every g in SE(3) (tests/sim checks it
// to 1e-9, and that a planted expert planning in world axes fails).
//
// Plan (slot frame):
//   1. approach, from the start to pre-insertion (upright, on the slot's axis, the tip
//      kPreInsertionTipHeight above the opening): the hand origin follows the cubic Bezier curve
//      start, via, pre + (0, 0, kArrivalLift), pre, so it arrives moving straight down the axis;
//      the orientation turns as R_start exp(e(s) log(R_start^T)) exp(b(s) w), with
//      e(s) = 3 s^2 - 2 s^3 (no angular velocity at the ends) and b(s) = 16 s^2 (1 - s)^2;
//      the via point and w are random: the via point at 30-70% of the way from the start to
//      pre-insertion, moved by up to +-3 cm in x and y and -1..+3 cm in z, and w a rotation
//      vector of up to 15 deg about a uniformly random axis. Different draws give demos that
//      pass on either side of the straight path: the demos are multimodal;
//   2. insertion: straight down the axis until the tip is kInsertionDepth deep;
//   3. control steps: the approach parameter is split evenly into as few steps as keep every
//      step within kMaxStepCm and kMaxStepDeg (with a 2% margin); the insertion likewise;
//   4. validation: every step's motion checked continuously (collision.hpp), the last pose
//      inserted (geometry.hpp), at most kMaxDemoSteps poses. An invalid solution is discarded
//      and counted, and a new via point is tried (up to ExpertOptions::attempts per scene).
#include <cstdint>
#include <random>
#include <vector>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/sim/insert3d/collision.hpp"
#include "handcentric/sim/insert3d/demos.hpp"
#include "handcentric/sim/insert3d/scenes.hpp"
#include "handcentric/sim/expert_run.hpp"

namespace handcentric::sim::insert3d {

/// Control-step limits: a step moves the hand origin at most this far and turns it at most this.
constexpr double kMaxStepCm = 0.5;
constexpr double kMaxStepDeg = 5.0;
/// Pre-insertion: the tip this far above the opening, on the axis, upright.
constexpr double kPreInsertionTipHeight = 1.0;
/// The approach's third Bezier point, this far above pre-insertion on the axis.
constexpr double kArrivalLift = 3.0;
/// Final pose: the tip this deep (kSuccessDepth = 5 is the bar, the slot is 6 deep).
constexpr double kInsertionDepth = 5.5;
/// A valid demo has at most this many poses.
constexpr int kMaxDemoSteps = 200;

struct ExpertOptions {
  bool random_via = true;  ///< false: the via point on the straight path, w = 0 (deterministic)
  int attempts = 8;        ///< random via points tried per scene before it counts as unsolved

  /// Throws InvalidArgument for attempts < 1.
  void validate() const;
};

struct ExpertPlan {
  bool valid = false;                       ///< collision-free and inserted within kMaxDemoSteps
  std::vector<RigidTransform> slot_T_hand;  ///< at each control step, [0] = start
};

/// One plan from slot_T_hand_start (one random via point drawn from rng), then validated.
ExpertPlan plan_in_slot_frame(const RigidTransform& slot_T_hand_start, std::mt19937_64& rng,
                              const CollisionChecker& checker,
                              const ExpertOptions& options = ExpertOptions());

using ExpertRun = BasicExpertRun<Demo>;

/// The expert on one scene: up to options.attempts plans from the stream (seed, index), the
/// first valid one mapped to the world (world_T_hand = world_T_slot slot_T_hand).
ExpertRun expert_demo(const TaskScene& scene, std::uint64_t seed, std::uint64_t index,
                      const CollisionChecker& checker,
                      const ExpertOptions& options = ExpertOptions());

/// The expert on every scene (scene i uses stream (seed, i)).
ExpertRun expert_demos(const std::vector<TaskScene>& scenes, std::uint64_t seed,
                       const CollisionChecker& checker,
                       const ExpertOptions& options = ExpertOptions());

}  // namespace handcentric::sim::insert3d
