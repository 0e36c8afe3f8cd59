#include "handcentric/props/checks/closed_loop.hpp"

#include <rapidcheck.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <random>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/props/checks/recorded_episodes.hpp"
#include "handcentric/props/observation/generators.hpp"
#include "handcentric/props/observation/recorded.hpp"
#include "handcentric/props/run.hpp"
#include "handcentric/props/tolerance.hpp"
#include "closed_loop_episode.hpp"

namespace handcentric::props {
namespace {

/// The objects an episode's camera sees, fixed in the world: the world points, and the
/// eye-in-hand points placed in the world at T_0.
std::vector<Eigen::Vector3d> objects_of(const Scene& scene) {
  std::vector<Eigen::Vector3d> objects = scene.world_points;
  const RigidTransform& T0 = scene.world_T_hand_history.front();
  for (const Eigen::Vector3d& h : scene.hand_points) objects.push_back(T0 * h);
  return objects;
}

/// One rollout of `steps` steps from `start`: the chunk returned at each step, whose first pose
/// is executed.
RolloutChunks rollout(const NoisyPolicy& policy, const Scene& start, int steps,
                      const std::vector<Eigen::VectorXd>& noises, const ClosedLoopOptions& loop) {
  const std::vector<Eigen::Vector3d> objects = objects_of(start);
  const std::size_t seen_in_hand = start.hand_points.size();
  Scene scene = start;
  RolloutChunks returned;
  if (loop.start_episode) loop.start_episode();
  for (int t = 0; t < steps; ++t) {
    const std::vector<const Scene*> one = {&scene};
    const std::vector<const Eigen::VectorXd*> noise = {&noises[static_cast<std::size_t>(t)]};
    returned.push_back(policy.act_fresh(one, noise).front());
    if (returned.back().empty()) throw InvalidArgument(policy.name() + " returned an empty chunk");
    const RigidTransform next = returned.back().front();
    // The hand moves to the executed pose: it is T_0 now, the history shifts by one.
    scene.world_T_hand_history.insert(scene.world_T_hand_history.begin(), next);
    scene.world_T_hand_history.pop_back();
    // The eye-in-hand camera sees the objects it saw at the start, from where the hand is.
    const RigidTransform hand_T_world = next.inverse();
    for (std::size_t i = 0; i < seen_in_hand; ++i)
      scene.hand_points[i] = hand_T_world * objects[start.world_points.size() + i];
  }
  return returned;
}

}  // namespace

Verdict check_policy_closed_loop(const NoisyPolicy& policy, Group group,
                                 const CheckOptions& options, const ClosedLoopOptions& loop) {
  if (options.shape.recorded && !options.shape.recorded->episode.empty())
    return check_policy_recorded_episodes(policy, group, options, loop);
  if (loop.episodes < 1 || loop.episodes > kMaxCases) {
    throw InvalidArgument("episodes=" + std::to_string(loop.episodes) + " is out of range: 1 to " +
                          std::to_string(kMaxCases));
  }
  if (loop.steps < 1 || loop.steps > 10000) {
    throw InvalidArgument("episode_length=" + std::to_string(loop.steps) +
                          " is out of range: 1 to 10000 steps");
  }
  if (loop.compared_from > 1) {
    throw InvalidArgument("compared_from=" + std::to_string(loop.compared_from) +
                          ": at most one executed pose precedes the chunk compared");
  }
  Verdict verdict = closed_loop_verdict(group, options);
  rc::Random random(options.seed ^ 0x6c6f6f70ULL);  // "loop": not the other checks' cases
  std::mt19937_64 perturb(options.seed);
  const rc::Gen<Scene> scenes = shaped_scene(options.shape);
  const rc::Gen<RigidTransform> elements = group_element(group, options.shape.planar);
  for (int e = 0; e < loop.episodes; ++e) {
    const Scene start = scenes(random.split(), rc::kNominalSize).value();
    const RigidTransform g = elements(random.split(), rc::kNominalSize).value();
    const std::vector<Eigen::VectorXd> noises =
        closed_loop_noises(policy.noise_dimension(), options, e, loop.steps);
    const Scene moved = g * start;
    ClosedLoopEpisode episode;
    episode.start = &start;
    episode.g = g;
    episode.a = rollout(policy, start, loop.steps, noises, loop);
    episode.b = rollout(policy, moved, loop.steps, noises, loop);
    episode.length_scale =
        std::max(rollout_scale({&start}, episode.a), rollout_scale({&moved}, episode.b));
    episode.nudged = [&] {
      const Scene nudged =
          rounding_perturbation(start, options.unit_roundoff, perturb, options.shape.planar);
      return rollout(policy, nudged, loop.steps, noises, loop);
    };
    episode.name =
        "closed loop, episode " + std::to_string(e) + " of " + std::to_string(loop.episodes);
    if (!judge_closed_loop_episode(verdict, episode, options, loop.compared_from)) return verdict;
  }
  if (verdict.cases == 0) verdict.invariant = false;  // no far episode: nothing was shown
  verdict.note = "closed loop: " + std::to_string(loop.episodes) + " episodes of " +
                 std::to_string(loop.steps) + " steps, each policy started afresh; a breaking " +
                 "that needs a longer episode or a state these episodes do not reach is not seen";
  return verdict;
}

}  // namespace handcentric::props
