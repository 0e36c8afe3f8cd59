#include "handcentric/props/checks/closed_loop.hpp"

#include <rapidcheck.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
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

/// One rollout of `steps` steps from `start`: the chunk returned at each step, whose first pose
/// is executed.
std::vector<std::vector<RigidTransform>> rollout(const NoisyPolicy& policy, const Scene& start,
                                                 int steps,
                                                 const std::vector<Eigen::VectorXd>& noises,
                                                 const ClosedLoopOptions& loop) {
  const std::vector<Eigen::Vector3d> objects = objects_of(start);
  const std::size_t seen_in_hand = start.hand_points.size();
  Scene scene = start;
  std::vector<std::vector<RigidTransform>> returned;
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

/// The largest pose_distance(b[k], g a[k]) over two chunks returned at one step, and the pose k
/// where it is (infinite when their lengths differ: a chunk is compared whole, as the pointwise
/// checks compare it, not only the pose executed).
std::pair<double, std::size_t> chunk_error(const std::vector<RigidTransform>& b,
                                           const RigidTransform& g,
                                           const std::vector<RigidTransform>& a,
                                           std::size_t compared_from) {
  if (a.size() != b.size()) return {std::numeric_limits<double>::infinity(), compared_from};
  std::pair<double, std::size_t> worst{0.0, compared_from};
  for (std::size_t k = compared_from; k < a.size(); ++k) {
    const double d = pose_distance(b[k], g * a[k]);
    if (std::isnan(d)) return {d, k};
    if (d > worst.first) worst = {d, k};
  }
  return worst;
}

double rollout_scale(const Scene& scene, const std::vector<std::vector<RigidTransform>>& chunks) {
  double L = length_scale(scene);
  for (const std::vector<RigidTransform>& chunk : chunks)
    for (const RigidTransform& T : chunk) L = std::max(L, T.translation().norm());
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
  if (loop.compared_from > 1) {
    throw InvalidArgument("compared_from=" + std::to_string(loop.compared_from) +
                          ": at most one executed pose precedes the chunk compared");
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
    const auto a = rollout(policy, start, loop.steps, noises, loop);
    const auto b = rollout(policy, moved, loop.steps, noises, loop);
    double L = std::max(rollout_scale(start, a), rollout_scale(moved, b));
    const double floor = options.relative_tolerance * (1.0 + L);
    std::vector<std::pair<double, std::size_t>> errors;  // per step: the error and its pose
    double worst = 0.0;
    for (int t = 0; t < loop.steps; ++t) {
      const std::size_t k = static_cast<std::size_t>(t);
      errors.push_back(chunk_error(b[k], g, a[k], loop.compared_from));
      const double e = errors.back().first;
      worst = std::isnan(e) || std::isnan(worst) ? std::numeric_limits<double>::quiet_NaN()
                                                 : std::max(worst, e);
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
    const auto a2 = rollout(policy, nudged, loop.steps, noises, loop);
    double response = 0.0;
    for (int t = 0; t < loop.steps; ++t) {
      const std::size_t k = static_cast<std::size_t>(t);
      const double d =
          chunk_error(a2[k], RigidTransform::identity(), a[k], loop.compared_from).first;
      response = std::isnan(d) || std::isnan(response) ? std::numeric_limits<double>::quiet_NaN()
                                                       : std::max(response, d);
    }
    const bool rounding =
        worst <= kRoundingMultiple * response && response <= rounding_cap(options.unit_roundoff, L);
    if (rounding) continue;
    verdict.invariant = false;
    // The first step the rollouts part: where the breaking enters the loop.
    std::size_t first = 0;
    while (first + 1 < errors.size() && errors[first].first <= floor) ++first;
    const std::size_t pose = errors[first].second;
    const bool same_length = a[first].size() == b[first].size();
    Witness w;
    w.scene = start;
    w.g = g;
    const std::size_t shown = same_length && pose < a[first].size() ? pose : 0;
    w.before = flat(g * a[first][shown]);
    w.after = flat(b[first][shown]);
    w.error = worst;
    w.tolerance = floor;
    w.length_scale = L;
    w.rounding_response = response;
    const std::string where =
        !same_length ? "returns " + std::to_string(b[first].size()) + " poses instead of " +
                           std::to_string(a[first].size())
        : pose == 0 ? "executes a pose that differs"
                    : "returns pose " + std::to_string(pose + 1 - loop.compared_from) +
                          " of the chunk compared differing";
    w.detail =
        "closed loop, episode " + std::to_string(e) + " of " + std::to_string(loop.episodes) +
        ": at step " + std::to_string(first + 1) + " of " + std::to_string(loop.steps) +
        " the policy " + where + " from g times the first rollout's by " +
        format_significant(errors[first].first, 4) + " (floor " + format_significant(floor, 3) +
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
