#include "handcentric/sim/insert3d/rollout.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/so3.hpp"
#include "handcentric/sim/insert3d/camera.hpp"
#include "handcentric/sim/insert3d/expert.hpp"
#include "handcentric/sim/scenes.hpp"

namespace handcentric::sim::insert3d {
namespace {

const double kMaxStepAngle = kMaxStepDeg * std::numbers::pi / 180.0;

/// The command clipped to the step limits along interpolate(); counts a clip.
RigidTransform clip(const RigidTransform& current, const RigidTransform& command, int& clipped) {
  const double step = (command.translation() - current.translation()).norm();
  const double angle = so3::angle(current.rotation().inverse_compose(command.rotation()).matrix());
  const double s = std::min(
      {1.0, step > 0.0 ? kMaxStepCm / step : 1.0, angle > 0.0 ? kMaxStepAngle / angle : 1.0});
  if (s >= 1.0) return command;
  ++clipped;
  return interpolate(current, command, s);
}

bool finite(const RigidTransform& pose) {
  return pose.matrix().allFinite();
}

}  // namespace

void RolloutOptions::validate() const {
  if (history < 0)
    throw InvalidArgument("rollout history H must be >= 0, got " + std::to_string(history));
  if (execute < 1)
    throw InvalidArgument("rollout execute must be >= 1 pose per chunk, got " +
                          std::to_string(execute));
  if (max_replans < 1)
    throw InvalidArgument("rollout max_replans must be >= 1, got " + std::to_string(max_replans));
}

Scene observe(const TaskScene& scene, const std::vector<RigidTransform>& world_T_hand, int history,
              const BladeSlotGeometry& geometry) {
  if (world_T_hand.empty())
    throw InvalidArgument("observe: no hand pose yet; give at least the start");
  Scene observation;
  const int last = static_cast<int>(world_T_hand.size()) - 1;
  for (int h = 0; h <= history; ++h) {
    observation.world_T_hand_history.push_back(
        world_T_hand[static_cast<std::size_t>(std::max(0, last - h))]);
  }
  const auto corners = opening_corners_in_hand(geometry, world_T_hand.back(), scene.world_T_slot);
  observation.hand_points.assign(corners.begin(), corners.end());
  return observation;
}

Rollout rollout(const ChunkPolicy& policy, const TaskScene& scene, std::uint64_t seed,
                const CollisionChecker& checker, const RolloutOptions& options) {
  options.validate();
  Rollout result;
  result.world_T_hand.push_back(scene.world_T_hand_start);
  const auto slot_T = [&scene](const RigidTransform& world_T_hand) {
    return scene.world_T_slot.inverse_compose(world_T_hand);
  };
  if (checker.collides(slot_T(scene.world_T_hand_start))) {
    result.outcome = Outcome::collision;
    return result;
  }
  for (int replan = 0; replan < options.max_replans; ++replan) {
    std::vector<RigidTransform> chunk;
    try {
      chunk = policy.act(observe(scene, result.world_T_hand, options.history, checker.geometry()),
                         stream_seed(seed, static_cast<std::uint64_t>(replan)));
    } catch (const NonFiniteAction&) {
      result.outcome = Outcome::invalid;
      return result;
    }
    if (chunk.empty())
      throw InvalidArgument("policy '" + policy.name() + "' returned an empty chunk");
    const int steps = std::min(options.execute, static_cast<int>(chunk.size()));
    for (int k = 0; k < steps; ++k) {
      if (!finite(chunk[static_cast<std::size_t>(k)])) {
        result.outcome = Outcome::invalid;
        return result;
      }
      const RigidTransform current = result.world_T_hand.back();
      const RigidTransform next = clip(current, chunk[static_cast<std::size_t>(k)], result.clipped);
      result.world_T_hand.push_back(next);
      if (checker.motion_collides(slot_T(current), slot_T(next))) {
        result.outcome = Outcome::collision;
        return result;
      }
      if (inserted(checker.geometry(), slot_T(next))) {
        result.outcome = Outcome::success;
        return result;
      }
    }
  }
  result.outcome = Outcome::timeout;
  return result;
}

RigidTransform hand_T_slot_from_corners(const std::vector<Eigen::Vector3d>& hand_corners) {
  if (hand_corners.size() != 4) {
    throw InvalidScene(
        "the 3D task's observation has 4 eye-in-hand points (the opening's corners), got " +
        std::to_string(hand_corners.size()));
  }
  const Eigen::Vector3d origin =
      0.25 * (hand_corners[0] + hand_corners[1] + hand_corners[2] + hand_corners[3]);
  const Eigen::Vector3d x = (hand_corners[1] - hand_corners[0]).normalized();
  const Eigen::Vector3d along_y = hand_corners[3] - hand_corners[0];
  const Eigen::Vector3d y = (along_y - along_y.dot(x) * x).normalized();
  Eigen::Matrix3d R;
  R << x, y, x.cross(y);
  return RigidTransform::unchecked(R, origin);
}

ClosedLoopExpert::ClosedLoopExpert(int chunk_length, const BladeSlotGeometry& geometry)
    : chunk_length_(chunk_length), checker_(geometry) {
  if (chunk_length < 1)
    throw InvalidArgument("expert chunk length must be >= 1, got " + std::to_string(chunk_length));
}

std::vector<RigidTransform> ClosedLoopExpert::act(const Scene& observation,
                                                  std::uint64_t noise_seed) const {
  const RigidTransform hand_T_slot = hand_T_slot_from_corners(observation.hand_points);
  const RigidTransform slot_T_hand = hand_T_slot.inverse();
  std::vector<RigidTransform> slot_T_plan;
  // Lined up: within 1e-3 cm of the axis and 1e-4 rad of upright (no blade point off by more
  // than ~1e-3 cm, 1% of the clearance), anywhere above the final depth.
  const bool on_axis =
      slot_T_hand.translation().head<2>().norm() < 1e-3 && slot_T_hand.rotation().angle() < 1e-4;
  if (on_axis) {
    // straight down the axis, exactly upright, one step at a time
    for (int k = 1; k <= chunk_length_; ++k) {
      const double z = std::max(kBladeLength - kInsertionDepth,
                                slot_T_hand.translation().z() - 0.98 * kMaxStepCm * k);
      slot_T_plan.push_back(RigidTransform::from_translation(Eigen::Vector3d(0.0, 0.0, z)));
    }
  } else {
    std::mt19937_64 rng(noise_seed);
    ExpertOptions options;
    options.random_via = false;
    const ExpertPlan plan = plan_in_slot_frame(slot_T_hand, rng, checker_, options);
    if (plan.slot_T_hand.empty()) {
      throw InvalidScene("insert3d-expert: no plan within " + std::to_string(kMaxDemoSteps) +
                         " steps from this pose; the slot is too far for the step limits");
    }
    for (int k = 1; k <= chunk_length_; ++k) {
      slot_T_plan.push_back(
          plan.slot_T_hand[std::min(static_cast<std::size_t>(k), plan.slot_T_hand.size() - 1)]);
    }
  }
  const RigidTransform world_T_slot = observation.world_T_hand0() * hand_T_slot;
  std::vector<RigidTransform> chunk;
  for (const RigidTransform& pose : slot_T_plan) chunk.push_back(world_T_slot * pose);
  return chunk;
}

}  // namespace handcentric::sim::insert3d
