#include "handcentric/props/checks/check.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/props/prefetch.hpp"
#include "handcentric/props/observation/recorded.hpp"
#include "handcentric/props/tolerance.hpp"
#include "check_runner.hpp"

namespace handcentric::props {
namespace detail {

Eigen::VectorXd flatten(const std::vector<RigidTransform>& chunk) {
  Eigen::VectorXd v(6 * static_cast<Eigen::Index>(chunk.size()));
  for (std::size_t k = 0; k < chunk.size(); ++k) {
    v.segment<3>(6 * static_cast<Eigen::Index>(k)) = chunk[k].translation();
    v.segment<3>(6 * static_cast<Eigen::Index>(k) + 3) = chunk[k].rotation().log();
  }
  return v;
}

double inf_distance(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  if (a.size() != b.size()) return std::numeric_limits<double>::infinity();
  if (a.size() == 0) return 0.0;
  return (a - b).lpNorm<Eigen::Infinity>();
}

double chunk_distance(const std::vector<RigidTransform>& a, const std::vector<RigidTransform>& b) {
  if (a.size() != b.size()) return std::numeric_limits<double>::infinity();
  double worst = 0.0;
  for (std::size_t k = 0; k < a.size(); ++k) worst = std::max(worst, distance(a[k], b[k]));
  return worst;
}

CaseOutcome decide_pointwise(const PointwiseSides& sides, const Scene& scene,
                             const RigidTransform& g, const CheckOptions& options) {
  constexpr int kRoundingDraws = 2;
  const bool planar = options.shape.planar;  // perturbations stay in the 2D task's plane
  CaseOutcome outcome;
  auto measure = [&](const Scene& s, Witness& witness) {
    const Scene moved = g * s;
    witness.scene = s;
    witness.g = g;
    sides.compare(s, witness);
    if (std::isnan(witness.error)) witness.error = std::numeric_limits<double>::infinity();
    witness.length_scale = std::max(length_scale(s), length_scale(moved));
    witness.tolerance = options.relative_tolerance * (1.0 + witness.length_scale);
    return moved;
  };
  // Each step names the scenes it is about to ask for, so that a batched map answers them
  // together (prefetch.hpp).
  auto ask_ahead_for = [&sides](const auto& scenes) {
    ask_ahead(scenes, [&sides](const Scene& s) {
      sides.ask(s);
      return 0;
    });
  };
  ask_ahead_for([&] { return std::vector<Scene>{scene, g * scene}; });
  const Scene moved = measure(scene, outcome.witness);
  Witness& w = outcome.witness;
  if (w.error <= w.tolerance) return outcome;  // 1. the floor
  // 2. The map's own rounding: how far each side moves when its inputs move by a few ulps.
  std::mt19937_64 rng(options.seed ^ 0x6a09e667f3bcc909ULL);
  std::vector<std::pair<const Scene*, Scene>> perturbed;  // (side, perturbed side), in draw order
  for (int d = 0; d < kRoundingDraws; ++d) {
    perturbed.emplace_back(&scene,
                           rounding_perturbation(scene, options.unit_roundoff, rng, planar));
    perturbed.emplace_back(&moved,
                           rounding_perturbation(moved, options.unit_roundoff, rng, planar));
  }
  ask_ahead_for([&] {
    std::vector<Scene> asked;
    for (const auto& [side, p] : perturbed) asked.push_back(p);
    return asked;
  });
  double response = 0.0;
  for (const auto& [side, p] : perturbed) response = std::max(response, sides.response(*side, p));
  if (std::isnan(response)) response = std::numeric_limits<double>::infinity();
  w.rounding_response = response;
  const double cap = rounding_cap(options.unit_roundoff, w.length_scale);
  if (response <= cap && w.error <= kRoundingMultiple * response) return outcome;
  // 3. Off the case: a bin edge moves away, a symmetry breaking stays.
  if (options.off_case_draws < 1) {
    outcome.holds = false;
    return outcome;
  }
  const double eta = off_case_scale(options.unit_roundoff);
  std::vector<Scene> nearby;
  for (int d = 0; d < options.off_case_draws; ++d)
    nearby.push_back(nearby_scene(scene, eta, rng, planar));
  ask_ahead_for([&] {
    std::vector<Scene> asked;
    for (const Scene& s : nearby) {
      asked.push_back(s);
      asked.push_back(g * s);
    }
    return asked;
  });
  for (int d = 0; d < options.off_case_draws; ++d) {
    Witness off;
    measure(nearby[static_cast<std::size_t>(d)], off);
    off.rounding_response = response;
    const double allowed = std::max(off.tolerance, kRoundingMultiple * std::min(response, cap));
    if (!(off.error <= allowed)) {
      off.off_case = true;
      outcome.witness = std::move(off);
      outcome.holds = false;
      return outcome;
    }
  }
  outcome.discontinuity = true;
  return outcome;
}

}  // namespace detail

namespace {

constexpr int kPointwiseShrinkBudget = 1000;

struct Equivariance {
  std::vector<RigidTransform> g_a;  // g * a(o)
  std::vector<RigidTransform> a_g;  // a(g * o)
};

Equivariance both_sides(const ChunkPolicy& policy, const Scene& scene, const RigidTransform& g,
                        std::uint64_t noise_seed) {
  Equivariance sides;
  for (const RigidTransform& world_T_handk : policy.act(scene, noise_seed))
    sides.g_a.push_back(g * world_T_handk);
  sides.a_g = policy.act(g * scene, noise_seed);
  return sides;
}

}  // namespace

SceneShape eye_in_hand_shape() {
  SceneShape shape;
  shape.max_world_points = 0;
  return shape;
}

SceneShape third_person_shape() {
  SceneShape shape;
  shape.min_world_points = 1;
  shape.max_world_points = 8;
  return shape;
}

SceneShape shape_for(View view) {
  return view == View::eye_in_hand ? eye_in_hand_shape() : third_person_shape();
}

View view_of(const SceneShape& shape) {
  return shape.max_world_points > 0 ? View::third_person : View::eye_in_hand;
}

CheckOptions options_for(View view) {
  CheckOptions options;
  options.shape = shape_for(view);
  return options;
}

CheckOptions eye_in_hand_options() {
  return options_for(View::eye_in_hand);
}

SceneFunction actions_of(std::shared_ptr<const Representation> representation) {
  return [representation](const Scene& scene) { return representation->encode_actions(scene); };
}

SceneFunction observation_of(std::shared_ptr<const Representation> representation) {
  return [representation](const Scene& scene) { return representation->encode_observation(scene); };
}

SceneFunction flow_input_of(std::shared_ptr<const FlowTarget> target, std::uint64_t noise_seed,
                            double t) {
  return [target, noise_seed, t](const Scene& scene) {
    return (*target)(scene, fixed_noise(target->noise_dimension(scene), noise_seed), t).input;
  };
}

SceneFunction flow_target_of(std::shared_ptr<const FlowTarget> target, std::uint64_t noise_seed,
                             double t) {
  return [target, noise_seed, t](const Scene& scene) {
    return (*target)(scene, fixed_noise(target->noise_dimension(scene), noise_seed), t).target;
  };
}

std::uint64_t pointwise_noise_seed(const CheckOptions& options, const Scene& scene,
                                   const RigidTransform& g) {
  return case_noise_seed(options.noise_seed, scene,
                         options.shape.recorded != nullptr ? &g : nullptr);
}

namespace {

/// The case (scene, g) of an invariance check of f: f(s) against f(g s), as check.hpp decides it.
detail::CaseOutcome decide_invariance(const SceneFunction& f, const Scene& scene,
                                      const RigidTransform& g, const CheckOptions& options) {
  detail::PointwiseSides sides;
  sides.compare = [&f, &g](const Scene& s, Witness& witness) {
    witness.before = f(s);
    witness.after = f(g * s);
    witness.error = detail::inf_distance(witness.before, witness.after);
  };
  sides.response = [&f](const Scene& a, const Scene& b) {
    return detail::inf_distance(f(a), f(b));
  };
  sides.ask = [&f](const Scene& s) { (void)f(s); };
  return detail::decide_pointwise(sides, scene, g, options);
}

}  // namespace

Verdict check_flow_invariance(std::shared_ptr<const FlowTarget> target, Component component,
                              Group group, const CheckOptions& options) {
  if (!target) throw InvalidArgument("check_flow_invariance needs a flow target, got null");
  if (component != Component::flow_input && component != Component::flow_target) {
    throw InvalidArgument("check_flow_invariance checks flow_input or flow_target, got " +
                          to_string(component));
  }
  const bool input = component == Component::flow_input;
  const double t = options.flow_time;
  auto run_case = [&](const Scene& scene, const RigidTransform& g) {
    // Each case its own eps, the same for s and g s (and the case's moves off it).
    const std::uint64_t noise_seed = pointwise_noise_seed(options, scene, g);
    const Eigen::VectorXd eps = fixed_noise(target->noise_dimension(scene), noise_seed);
    const SceneFunction f = [&](const Scene& s) {
      FlowSample example = (*target)(s, eps, t);
      return input ? std::move(example.input) : std::move(example.target);
    };
    detail::CaseOutcome outcome = decide_invariance(f, scene, g, options);
    outcome.witness.noise_seed = noise_seed;
    return outcome;
  };
  return detail::run_check(run_case, component, group, Mode::pointwise, options, options.cases,
                           kPointwiseShrinkBudget);
}

Verdict check_invariance(const SceneFunction& f, Component component, Group group,
                         const CheckOptions& options) {
  auto run_case = [&f, &options](const Scene& scene, const RigidTransform& g) {
    return decide_invariance(f, scene, g, options);
  };
  return detail::run_check(run_case, component, group, Mode::pointwise, options, options.cases,
                           kPointwiseShrinkBudget);
}

double recompute_error(const SceneFunction& f, const Witness& witness) {
  return detail::inf_distance(f(witness.scene), f(witness.g * witness.scene));
}

Verdict check_equivariance(const ChunkPolicy& policy, Group group, const CheckOptions& options) {
  auto run_case = [&policy, &options](const Scene& scene, const RigidTransform& g) {
    // Each case its own seed of the policy's noise, the same for o and g o.
    const std::uint64_t noise_seed = pointwise_noise_seed(options, scene, g);
    detail::PointwiseSides sides;
    sides.compare = [&policy, &g, noise_seed](const Scene& s, Witness& witness) {
      const Equivariance both = both_sides(policy, s, g, noise_seed);
      witness.before = detail::flatten(both.g_a);
      witness.after = detail::flatten(both.a_g);
      witness.error = detail::chunk_distance(both.g_a, both.a_g);  // eq. (4)
    };
    sides.response = [&policy, noise_seed](const Scene& a, const Scene& b) {
      return detail::chunk_distance(policy.act(a, noise_seed), policy.act(b, noise_seed));
    };
    sides.ask = [&policy, noise_seed](const Scene& s) { (void)policy.act(s, noise_seed); };
    detail::CaseOutcome outcome = detail::decide_pointwise(sides, scene, g, options);
    outcome.witness.noise_seed = noise_seed;
    return outcome;
  };
  return detail::run_check(run_case, Component::policy, group, Mode::pointwise, options,
                           options.cases, kPointwiseShrinkBudget);
}

double recompute_equivariance_error(const ChunkPolicy& policy, const Witness& witness,
                                    std::uint64_t noise_seed) {
  const Equivariance sides =
      both_sides(policy, witness.scene, witness.g, witness.noise_seed.value_or(noise_seed));
  return detail::chunk_distance(sides.g_a, sides.a_g);
}

}  // namespace handcentric::props
