#pragma once
// The expert of Sec. 4.2: "demonstrations are collected from a trajectory optimization pipeline
// by discarding invalid solutions".
//
// Everything is computed in the hole frame, so the expert is equivariant by construction: a
// global transform g of a scene maps its demo T_t to g T_t (tests/sim checks it).
//
// Plan (hole frame, poses as q = (theta, x, y)):
//   1. approach: waypoints q_0 = start, ..., q_N = pre-insertion (on the hole axis, peg tip
//      kPreInsertionTipHeight above the opening), optimized CHOMP-style (Ratliff et al. 2009):
//        cost = sum_i |q_{i+1} - 2 q_i + q_{i-1}|^2          (smoothness: squared accelerations,
//                                                              theta scaled by kAngleScale cm/rad)
//             + w_via |q_m - via|^2                          (a random via point: diverse demos)
//             + w_arr |q_{N-1} - (q_N + s e_y)|^2              (arrival along the hole axis: the
//                                                              acceleration at q_N, continuing
//                                                              into the insertion,
//                                                              s = |q_0 - q_N|/N)
//             + w_col sum_i penalty(q_i)                     (hinge on a smooth clearance proxy)
//      with preconditioned gradient steps q <- q - eta A^{-1} grad, A the quadratic part;
//   2. insertion: straight down the hole axis to the tip kInsertionDepth deep;
//   3. resampled at the control step (each step moves the hand at most step_cm and step_deg);
//   4. validated with the exact continuous collision check (collision.hpp) and the success test;
//      an invalid solution is discarded and counted, and a new random via point is tried.
#include <cstdint>
#include <random>
#include <vector>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/sim/collision.hpp"
#include "handcentric/sim/demos.hpp"
#include "handcentric/sim/scenes.hpp"
#include "handcentric/sim/expert_run.hpp"

namespace handcentric::sim {

/// Control-step limits shared by demos and rollouts: a step moves the hand at most this far.
constexpr double kMaxStepCm = 0.5;
constexpr double kMaxStepDeg = 5.0;
/// Pre-insertion: the peg tip this far above the opening, on the axis, upright.
constexpr double kPreInsertionTipHeight = 1.0;
/// Final pose: the tip this deep (kSuccessDepth = 5.0 is the bar, the hole is 6.0 deep).
constexpr double kInsertionDepth = 5.5;
/// A valid demo has at most this many poses, so it fits a rollout's budget (25 replans x 8 steps).
constexpr int kMaxDemoSteps = 200;

struct ExpertOptions {
  int waypoints = 24;            ///< approach segments N
  int iterations = 60;           ///< optimizer steps
  bool random_via = true;        ///< false: no via point (the deterministic closed-loop expert)
  int attempts = 8;              ///< random via points tried per scene before it counts as unsolved
  double arrival_weight = 10.0;  ///< w_arr; 0 turns down into the hole in one step
};

struct ExpertPlan {
  bool valid = false;                       ///< collision-free and successful
  std::vector<RigidTransform> hole_T_hand;  ///< at each control step, [0] = start
};

/// One optimization from hole_T_hand_start (one random via point drawn from rng), then
/// validated. Throws InvalidArgument for a non-planar start.
ExpertPlan plan_in_hole_frame(const RigidTransform& hole_T_hand_start, std::mt19937_64& rng,
                              const CollisionChecker& checker,
                              const ExpertOptions& options = ExpertOptions());

using ExpertRun = BasicExpertRun<Demo>;

/// The expert on one scene: up to options.attempts optimizations from the stream (seed, index),
/// the first valid one mapped to the world (world_T_hand = world_T_hole hole_T_hand).
ExpertRun expert_demo(const TaskScene& scene, std::uint64_t seed, std::uint64_t index,
                      const CollisionChecker& checker,
                      const ExpertOptions& options = ExpertOptions());

/// The expert on every scene (scene i uses stream (seed, i)): demos, discards, unsolved scenes.
ExpertRun expert_demos(const std::vector<TaskScene>& scenes, std::uint64_t seed,
                       const CollisionChecker& checker,
                       const ExpertOptions& options = ExpertOptions());

/// Resamples a path of planar poses (piecewise linear in (theta, x, y)) at the control step:
/// consecutive output poses differ by at most step_cm and step_deg; the ends are kept exactly.
std::vector<RigidTransform> resample_at_control_step(const std::vector<RigidTransform>& path,
                                                     double step_cm = kMaxStepCm,
                                                     double step_deg = kMaxStepDeg);

}  // namespace handcentric::sim
