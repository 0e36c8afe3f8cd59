#include "closed_loop_episode.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "handcentric/core/format.hpp"
#include "handcentric/props/noisy_policy.hpp"
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

/// NaN-propagating max.
double worse(double a, double b) {
  return std::isnan(a) || std::isnan(b) ? std::numeric_limits<double>::quiet_NaN() : std::max(a, b);
}

}  // namespace

Verdict closed_loop_verdict(Group group, const CheckOptions& options) {
  Verdict verdict;
  verdict.component = Component::policy;
  verdict.group = group;
  verdict.mode = Mode::closed_loop;
  verdict.view = view_of(options.shape);
  verdict.seed = options.seed;
  verdict.relative_tolerance = options.relative_tolerance;
  verdict.invariant = true;
  return verdict;
}

std::vector<Eigen::VectorXd> closed_loop_noises(Eigen::Index dimension, const CheckOptions& options,
                                                int episode, int steps) {
  std::vector<Eigen::VectorXd> noises;
  for (int t = 0; t < steps; ++t) {
    noises.push_back(fixed_noise(dimension, options.noise_seed +
                                                1000003ULL * static_cast<unsigned>(episode) +
                                                static_cast<unsigned>(t)));
  }
  return noises;
}

double rollout_scale(const std::vector<const Scene*>& scenes, const RolloutChunks& chunks) {
  double L = 0.0;
  for (const Scene* scene : scenes) L = std::max(L, length_scale(*scene));
  for (const std::vector<RigidTransform>& chunk : chunks)
    for (const RigidTransform& T : chunk) L = std::max(L, T.translation().norm());
  return L;
}

bool judge_closed_loop_episode(Verdict& verdict, const ClosedLoopEpisode& episode,
                               const CheckOptions& options, std::size_t compared_from) {
  const RolloutChunks& a = episode.a;
  const RolloutChunks& b = episode.b;
  const double L = episode.length_scale;
  const double floor = options.relative_tolerance * (1.0 + L);
  std::vector<std::pair<double, std::size_t>> errors;  // per step: the error and its pose
  double worst = 0.0;
  for (std::size_t t = 0; t < a.size(); ++t) {
    errors.push_back(chunk_error(b[t], episode.g, a[t], compared_from));
    worst = worse(worst, errors.back().first);
  }
  if (near_identity(episode.g, *episode.start))
    ++verdict.near_identity_cases;
  else
    ++verdict.cases;
  verdict.max_error = std::isnan(worst) ? worst : std::max(verdict.max_error, worst);
  if (worst <= floor) return true;
  // Above the floor: the rollout's own response to rounding of its start.
  const RolloutChunks a2 = episode.nudged();
  double response = 0.0;
  for (std::size_t t = 0; t < a.size(); ++t)
    response =
        worse(response, chunk_error(a2[t], RigidTransform::identity(), a[t], compared_from).first);
  const bool rounding =
      worst <= kRoundingMultiple * response && response <= rounding_cap(options.unit_roundoff, L);
  if (rounding) return true;
  verdict.invariant = false;
  // The first step the rollouts part: where the breaking enters the loop.
  std::size_t first = 0;
  while (first + 1 < errors.size() && errors[first].first <= floor) ++first;
  const std::size_t pose = errors[first].second;
  const bool same_length = a[first].size() == b[first].size();
  Witness w;
  w.scene = *episode.start;
  w.g = episode.g;
  const std::size_t shown = same_length && pose < a[first].size() ? pose : 0;
  w.before = flat(episode.g * a[first][shown]);
  w.after = flat(b[first][shown]);
  w.error = worst;
  w.tolerance = floor;
  w.length_scale = L;
  w.rounding_response = response;
  const std::string where =
      !same_length ? "returns " + std::to_string(b[first].size()) + " poses instead of " +
                         std::to_string(a[first].size())
      : pose == 0 ? "executes a pose that differs"
                  : "returns pose " + std::to_string(pose + 1 - compared_from) +
                        " of the chunk compared differing";
  w.detail = episode.name + ": at step " + std::to_string(first + 1) + " of " +
             std::to_string(a.size()) + " the policy " + where +
             " from g times the first rollout's by " + format_significant(errors[first].first, 4) +
             " (floor " + format_significant(floor, 3) + "), the largest difference over the " +
             "episode " + format_significant(worst, 4);
  verdict.witness = w;
  return false;
}

}  // namespace handcentric::props
