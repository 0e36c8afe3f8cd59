#include "handcentric/props/checks/closed_loop.hpp"

#include <rapidcheck.h>

#include <algorithm>
#include <random>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/props/observation/generators.hpp"
#include "handcentric/props/run.hpp"
#include "handcentric/props/tolerance.hpp"

namespace handcentric::props {
namespace {

/// |R_a - R_b|_F + |p_a - p_b|: the pointwise checks' distance of two poses.
double pose_distance(const RigidTransform& a, const RigidTransform& b) {
  return (a.rotation().matrix() - b.rotation().matrix()).norm() +
         (a.translation() - b.translation()).norm();
}

Eigen::VectorXd flat(const RigidTransform& T) {
  Eigen::VectorXd v(6);
  v << T.translation(), T.rotation().log();
  return v;
}

/// The objects an episode's camera sees, fixed in the world: the world points, and the
/// eye-in-hand points placed in the world at T_0.
std::vector<Eigen::Vector3d> objects_of(const Scene& scene) {
  std::vector<Eigen::Vector3d> objects = scene.world_points;
  const RigidTransform& T0 = scene.world_T_hand_history.front();
  for (const Eigen::Vector3d& h : scene.hand_points) objects.push_back(T0 * h);
  return objects;
}

/// One rollout of `steps` steps from `start`: the executed poses.
std::vector<RigidTransform> rollout(const NoisyPolicy& policy, const Scene& start, int steps,
                                    const std::vector<Eigen::VectorXd>& noises,
                                    const ClosedLoopOptions& loop) {
  const std::vector<Eigen::Vector3d> objects = objects_of(start);
  const std::size_t seen_in_hand = start.hand_points.size();
  Scene scene = start;
  std::vector<RigidTransform> executed;
  if (loop.start_episode) loop.start_episode();
  for (int t = 0; t < steps; ++t) {
    const std::vector<const Scene*> one = {&scene};
    const std::vector<const Eigen::VectorXd*> noise = {&noises[static_cast<std::size_t>(t)]};
    const std::vector<RigidTransform> chunk = policy.act_fresh(one, noise).front();
    if (chunk.empty()) throw InvalidArgument(policy.name() + " returned an empty chunk");
    const RigidTransform next = chunk.front();
    executed.push_back(next);
    // The hand moves to the executed pose: it is T_0 now, the history shifts by one.
    scene.world_T_hand_history.insert(scene.world_T_hand_history.begin(), next);
    scene.world_T_hand_history.pop_back();
    // The eye-in-hand camera sees the objects it saw at the start, from where the hand is.
    const RigidTransform hand_T_world = next.inverse();
    for (std::size_t i = 0; i < seen_in_hand; ++i)
      scene.hand_points[i] = hand_T_world * objects[start.world_points.size() + i];
  }
  return executed;
}

double rollout_scale(const Scene& scene, const std::vector<RigidTransform>& poses) {
  double L = length_scale(scene);
  for (const RigidTransform& T : poses) L = std::max(L, T.translation().norm());
  return L;
}

}  // namespace

Verdict check_policy_closed_loop(const NoisyPolicy& policy, Group group,
                                 const CheckOptions& options, const ClosedLoopOptions& loop) {
  if (loop.episodes < 1 || loop.episodes > kMaxCases) {
    throw InvalidArgument("episodes=" + std::to_string(loop.episodes) + " is out of range: 1 to " +
                          std::to_string(kMaxCases));
  }
  if (loop.steps < 1 || loop.steps > 10000) {
    throw InvalidArgument("episode_length=" + std::to_string(loop.steps) +
                          " is out of range: 1 to 10000 steps");
  }
  Verdict verdict;
  verdict.component = Component::policy;
  verdict.group = group;
  verdict.mode = Mode::closed_loop;
  verdict.view = view_of(options.shape);
  verdict.seed = options.seed;
  verdict.relative_tolerance = options.relative_tolerance;
  verdict.invariant = true;
  rc::Random random(options.seed ^ 0x6c6f6f70ULL);  // "loop": not the other checks' cases
  std::mt19937_64 perturb(options.seed);
  const rc::Gen<Scene> scenes = shaped_scene(options.shape);
  const rc::Gen<RigidTransform> elements = group_element(group, options.shape.planar);
  for (int e = 0; e < loop.episodes; ++e) {
    const Scene start = scenes(random.split(), rc::kNominalSize).value();
    const RigidTransform g = elements(random.split(), rc::kNominalSize).value();
    std::vector<Eigen::VectorXd> noises;
    for (int t = 0; t < loop.steps; ++t) {
      noises.push_back(fixed_noise(
          policy.noise_dimension(),
          options.noise_seed + 1000003ULL * static_cast<unsigned>(e) + static_cast<unsigned>(t)));
    }
    const Scene moved = g * start;
    const std::vector<RigidTransform> a = rollout(policy, start, loop.steps, noises, loop);
    const std::vector<RigidTransform> b = rollout(policy, moved, loop.steps, noises, loop);
    double L = std::max(rollout_scale(start, a), rollout_scale(moved, b));
    const double floor = options.relative_tolerance * (1.0 + L);
    std::vector<double> errors;
    double worst = 0.0;
    for (int t = 0; t < loop.steps; ++t) {
      const std::size_t k = static_cast<std::size_t>(t);
      errors.push_back(pose_distance(b[k], g * a[k]));
      worst = std::isnan(errors.back()) ? errors.back() : std::max(worst, errors.back());
    }
    const bool near = near_identity(g, start);
    if (!near)
      ++verdict.cases;
    else
      ++verdict.near_identity_cases;
    verdict.max_error = std::isnan(worst) ? worst : std::max(verdict.max_error, worst);
    if (worst <= floor) continue;
    // Above the floor: the rollout's own response to rounding of its start.
    const Scene nudged =
        rounding_perturbation(start, options.unit_roundoff, perturb, options.shape.planar);
    const std::vector<RigidTransform> a2 = rollout(policy, nudged, loop.steps, noises, loop);
    double response = 0.0;
    for (int t = 0; t < loop.steps; ++t) {
      const double d =
          pose_distance(a2[static_cast<std::size_t>(t)], a[static_cast<std::size_t>(t)]);
      response = std::isnan(d) ? d : std::max(response, d);
    }
    const bool rounding =
        worst <= kRoundingMultiple * response && response <= rounding_cap(options.unit_roundoff, L);
    if (rounding) continue;
    verdict.invariant = false;
    // The first step the rollouts part: where the breaking enters the loop.
    std::size_t first = 0;
    while (first + 1 < errors.size() && errors[first] <= floor) ++first;
    Witness w;
    w.scene = start;
    w.g = g;
    w.before = flat(g * a[first]);
    w.after = flat(b[first]);
    w.error = worst;
    w.tolerance = floor;
    w.length_scale = L;
    w.rounding_response = response;
    w.detail = "closed loop, episode " + std::to_string(e) + " of " +
               std::to_string(loop.episodes) + ": the executed pose at step " +
               std::to_string(first + 1) + " of " + std::to_string(loop.steps) +
               " differs from g times the first rollout's by " +
               format_significant(errors[first], 4) + " (floor " + format_significant(floor, 3) +
               "), the largest difference over the episode " + format_significant(worst, 4);
    verdict.witness = w;
    return verdict;
  }
  if (verdict.cases == 0) verdict.invariant = false;  // no far episode: nothing was shown
  verdict.note = "closed loop: " + std::to_string(loop.episodes) + " episodes of " +
                 std::to_string(loop.steps) + " steps, each policy started afresh; a breaking " +
                 "that needs a longer episode or a state these episodes do not reach is not seen";
  return verdict;
}

}  // namespace handcentric::props
