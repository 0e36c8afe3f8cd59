#include "handcentric/props/check.hpp"

#include <cmath>
#include <exception>
#include <iostream>
#include <sstream>
#include <limits>
#include <random>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/props/tolerance.hpp"
#include "check_runner.hpp"
#include "rapidcheck/detail/TestListenerAdapter.h"

namespace handcentric::props {
namespace detail {
namespace {

// RapidCheck prints "Using configuration: seed=..." on std::cerr the first time its global
// configuration is read. The checks pass their own seed, so that line would only mislead: read
// the configuration once with std::cerr muted.
void load_rapidcheck_configuration_quietly() {
  static const bool loaded = [] {
    std::ostringstream sink;
    std::streambuf* const saved = std::cerr.rdbuf(sink.rdbuf());
    try {
      (void)rc::detail::configuration();
    } catch (...) {
    }
    std::cerr.rdbuf(saved);
    return true;
  }();
  (void)loaded;
}

}  // namespace

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

void run_silently(const std::function<void()>& property, const std::string& description,
                  std::uint64_t seed, int cases) {
  load_rapidcheck_configuration_quietly();
  rc::detail::TestParams params;  // not rc::detail::configuration(): it reads RC_PARAMS and prints
  params.seed = seed;
  params.maxSuccess = cases;
  rc::detail::TestMetadata metadata;
  metadata.id = metadata.description = description;
  rc::detail::TestListenerAdapter silent;  // the caller records the result; print nothing
  rc::detail::checkTestable(property, metadata, params, silent);
}

Verdict run_check(const CaseFunction& run_case, Component component, Group group, Mode mode,
                  const CheckOptions& options, int cases, int shrink_budget) {
  if (cases < 1)
    throw InvalidArgument("a check needs at least 1 case, got " + std::to_string(cases));
  if (!(options.relative_tolerance > 0.0) || !std::isfinite(options.relative_tolerance)) {
    throw InvalidArgument("relative_tolerance must be a positive number, got " +
                          std::to_string(options.relative_tolerance));
  }
  Verdict verdict;
  verdict.component = component;
  verdict.group = group;
  verdict.mode = mode;
  verdict.view = view_of(options.shape);
  verdict.seed = options.seed;
  verdict.relative_tolerance = options.relative_tolerance;
  bool searching = true;  // false once the first failure is seen: then RapidCheck shrinks
  std::exception_ptr error;
  const SceneShape shape = options.shape;
  int shrink_evaluations = 0;
  auto property = [&] {
    if (error) return;  // a broken function under test: let RapidCheck finish at once
    if (!searching && ++shrink_evaluations > (options.shrink ? shrink_budget : 0))
      return;  // budget spent: keep the witness
    const Scene scene = *props::scene(shape);
    const RigidTransform g = *group_element(group);
    CaseOutcome outcome;
    try {
      outcome = run_case(scene, g);
    } catch (const Error&) {
      error = std::current_exception();
      return;
    }
    if (searching) {
      const double e = std::isnan(outcome.witness.error) ? std::numeric_limits<double>::infinity()
                                                         : outcome.witness.error;
      verdict.max_error = std::max(verdict.max_error, e);
      verdict.min_p_value = std::min(verdict.min_p_value, outcome.witness.p_value);
      if (near_identity(g, scene)) {
        ++verdict.near_identity_cases;
      } else {
        ++verdict.cases;
      }
    }
    if (!outcome.holds) {
      searching = false;
      verdict.witness = std::move(outcome.witness);  // the last failure is the shrunk one
      RC_FAIL("not invariant");
    }
  };
  run_silently(property, to_string(component) + " under " + to_string(group), options.seed, cases);
  if (error) std::rethrow_exception(error);
  verdict.invariant = !verdict.witness.has_value() && verdict.cases >= 1;
  return verdict;
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

Eigen::VectorXd fixed_noise(Eigen::Index n, std::uint64_t seed) {
  // The first n normals of one stream: cache a long prefix per thread (seeding a Mersenne
  // twister costs more than the checks that use it).
  thread_local std::uint64_t cached_seed = 0;
  thread_local Eigen::VectorXd cached;
  if (cached.size() < n || cached_seed != seed) {
    std::mt19937_64 rng(seed);
    cached.resize(std::max<Eigen::Index>(n, 256));
    for (Eigen::Index i = 0; i < cached.size(); ++i) cached(i) = standard_normal(rng);
    cached_seed = seed;
  }
  return cached.head(n);
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

Verdict check_invariance(const SceneFunction& f, Component component, Group group,
                         const CheckOptions& options) {
  const double relative = options.relative_tolerance;
  auto run_case = [&f, relative](const Scene& scene, const RigidTransform& g) {
    detail::CaseOutcome outcome;
    const Scene moved = g * scene;
    outcome.witness.scene = scene;
    outcome.witness.g = g;
    outcome.witness.before = f(scene);
    outcome.witness.after = f(moved);
    outcome.witness.error = detail::inf_distance(outcome.witness.before, outcome.witness.after);
    outcome.witness.tolerance = pointwise_tolerance(scene, moved, relative);
    outcome.holds = outcome.witness.error <= outcome.witness.tolerance;  // false for NaN
    return outcome;
  };
  return detail::run_check(run_case, component, group, Mode::pointwise, options, options.cases,
                           kPointwiseShrinkBudget);
}

double recompute_error(const SceneFunction& f, const Witness& witness) {
  return detail::inf_distance(f(witness.scene), f(witness.g * witness.scene));
}

Verdict check_equivariance(const ChunkPolicy& policy, Group group, const CheckOptions& options) {
  const std::uint64_t noise_seed = options.noise_seed;
  const double relative = options.relative_tolerance;
  auto run_case = [&policy, noise_seed, relative](const Scene& scene, const RigidTransform& g) {
    detail::CaseOutcome outcome;
    const Equivariance sides = both_sides(policy, scene, g, noise_seed);
    outcome.witness.scene = scene;
    outcome.witness.g = g;
    outcome.witness.before = detail::flatten(sides.g_a);
    outcome.witness.after = detail::flatten(sides.a_g);
    outcome.witness.error = detail::chunk_distance(sides.g_a, sides.a_g);  // eq. (4)
    outcome.witness.tolerance = pointwise_tolerance(scene, g * scene, relative);
    outcome.holds = outcome.witness.error <= outcome.witness.tolerance;
    return outcome;
  };
  return detail::run_check(run_case, Component::policy, group, Mode::pointwise, options,
                           options.cases, kPointwiseShrinkBudget);
}

double recompute_equivariance_error(const ChunkPolicy& policy, const Witness& witness,
                                    std::uint64_t noise_seed) {
  const Equivariance sides = both_sides(policy, witness.scene, witness.g, noise_seed);
  return detail::chunk_distance(sides.g_a, sides.a_g);
}

}  // namespace handcentric::props
