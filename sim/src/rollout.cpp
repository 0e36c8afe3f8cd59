// Closed-loop chunked rollouts (rollout.hpp).
#include "handcentric/sim/rollout.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "handcentric/core/errors.hpp"
#include "handcentric/sim/demos.hpp"

namespace handcentric::sim {
namespace {

/// Limits are met up to this relative slack (rounding of poses that were resampled exactly).
constexpr double kLimitSlack = 1e-9;

bool finite(const RigidTransform& pose) {
  return pose.rotation().matrix().allFinite() && pose.translation().allFinite();
}

}  // namespace

void RolloutOptions::validate() const {
  if (history < 0)
    throw InvalidArgument("rollout: history must be >= 0, got " + std::to_string(history));
  if (execute < 1)
    throw InvalidArgument("rollout: execute must be >= 1, got " + std::to_string(execute));
  if (max_replans < 1)
    throw InvalidArgument("rollout: max_replans must be >= 1, got " + std::to_string(max_replans));
  if (!(max_step_cm > 0.0) || !(max_step_deg > 0.0)) {
    throw InvalidArgument("rollout: step limits must be positive, got " +
                          std::to_string(max_step_cm) + " cm, " + std::to_string(max_step_deg) +
                          " deg");
  }
}

RolloutOptions RolloutOptions::for_policy(int history, int execute) {
  RolloutOptions options;
  options.history = history;
  options.execute = execute;
  options.max_replans = execute >= 1 ? (kStepBudget + execute - 1) / execute : 1;
  options.validate();
  return options;
}

Scene observation(const RigidTransform& world_T_hole,
                  const std::vector<RigidTransform>& world_T_hand, int history,
                  const PegHoleGeometry& geometry) {
  if (world_T_hand.empty()) throw InvalidArgument("observation: the trajectory is empty");
  if (history < 0)
    throw InvalidArgument("observation: history must be >= 0, got " + std::to_string(history));
  const int last = static_cast<int>(world_T_hand.size()) - 1;
  Scene scene;
  for (int h = 0; h <= history; ++h)
    scene.world_T_hand_history.push_back(
        world_T_hand[static_cast<std::size_t>(std::max(0, last - h))]);
  scene.hand_points = eye_in_hand_points(world_T_hole, world_T_hand.back(), geometry);
  return scene;
}

Rollout rollout(const ChunkPolicy& policy, const TaskScene& scene, const CollisionChecker& checker,
                std::uint64_t seed, const RolloutOptions& options) {
  options.validate();
  const double max_step_rad = options.max_step_deg * std::numbers::pi / 180.0;
  Rollout result;
  result.world_T_hand.push_back(scene.world_T_hand_start);
  RigidTransform hole_T_hand = scene.world_T_hole.inverse_compose(scene.world_T_hand_start);
  if (checker.collides(hole_T_hand)) {
    result.outcome = Outcome::collision;
    return result;
  }
  // Ends the rollout as invalid, or throws with stop_on_invalid.
  const auto invalid = [&](const std::string& reason) {
    if (options.stop_on_invalid) throw NonFiniteAction(reason);
    result.outcome = Outcome::invalid;
    result.invalid_reason = reason;
    return result;
  };
  for (int replan = 0; replan < options.max_replans; ++replan) {
    const Scene observed =
        observation(scene.world_T_hole, result.world_T_hand, options.history, checker.geometry());
    std::vector<RigidTransform> chunk;
    try {
      chunk = policy.act(observed, stream_seed(seed, static_cast<std::uint64_t>(replan)));
    } catch (const NonFiniteAction& error) {
      ++result.replans;
      return invalid("policy '" + policy.name() + "' at replan " + std::to_string(replan) + ": " +
                     error.what());
    }
    ++result.replans;
    if (chunk.empty()) {
      throw InvalidArgument("policy '" + policy.name() + "' returned an empty chunk at replan " +
                            std::to_string(replan));
    }
    const int n = std::min(options.execute, static_cast<int>(chunk.size()));
    for (int k = 0; k < n; ++k) {
      const RigidTransform& world_T_command = chunk[static_cast<std::size_t>(k)];
      if (!finite(world_T_command)) {
        return invalid("policy '" + policy.name() + "' returned a non-finite pose (chunk entry " +
                       std::to_string(k) + " at replan " + std::to_string(replan) + ")");
      }
      // the commanded pose in the hole frame, projected onto the plane
      const Eigen::Vector3d q =
          planar_coordinates(scene.world_T_hole.inverse_compose(world_T_command));
      RigidTransform hole_T_next = RigidTransform::planar(q(0), q(1), q(2));
      const RigidTransform delta = hole_T_hand.inverse_compose(hole_T_next);
      const double fraction =
          std::min({1.0, options.max_step_cm * (1.0 + kLimitSlack) / delta.translation().norm(),
                    max_step_rad * (1.0 + kLimitSlack) / delta.rotation().angle()});
      if (fraction < 1.0) {
        ++result.clipped;
        hole_T_next = interpolate_planar(hole_T_hand, hole_T_next, fraction);
      }
      const bool hit = checker.motion_collides(hole_T_hand, hole_T_next);
      hole_T_hand = hole_T_next;
      result.world_T_hand.push_back(scene.world_T_hole * hole_T_hand);
      ++result.steps;
      if (hit) {
        result.outcome = Outcome::collision;
        return result;
      }
      if (is_inserted(hole_T_hand, checker.geometry())) {
        result.outcome = Outcome::success;
        return result;
      }
    }
  }
  result.outcome = Outcome::timeout;
  return result;
}

RolloutSummary evaluate(const ChunkPolicy& policy, const std::vector<TaskScene>& scenes,
                        const CollisionChecker& checker, std::uint64_t seed,
                        const RolloutOptions& options) {
  RolloutSummary summary;
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    Rollout r;
    try {
      r = rollout(policy, scenes[i], checker, stream_seed(seed, i), options);
    } catch (const NonFiniteAction& error) {
      throw NonFiniteAction("scene " + std::to_string(i) + ": " + error.what());
    }
    ++summary.trials;
    summary.clipped += r.clipped;
    switch (r.outcome) {
      case Outcome::success:
        ++summary.success;
        break;
      case Outcome::collision:
        ++summary.collision;
        break;
      case Outcome::timeout:
        ++summary.timeout;
        break;
      case Outcome::invalid:
        if (summary.invalid++ == 0) {
          summary.first_invalid_scene = static_cast<int>(i);
          summary.first_invalid_reason = r.invalid_reason;
        }
        break;
    }
  }
  return summary;
}

}  // namespace handcentric::sim
