#include "handcentric/props/checks/check.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <iostream>
#include <sstream>
#include <limits>
#include <optional>
#include <random>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/core/sampling.hpp"
#include "handcentric/props/prefetch.hpp"
#include "handcentric/props/observation/recorded.hpp"
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

std::pair<Scene, RigidTransform> draw_case(const SceneShape& shape, Group group) {
  if (shape.recorded) return *recorded_case(shape, group);
  if (shape.workspace) return *case_in_workspace(shape, group, *shape.workspace);
  // Two draws, in this order, as every verdict and witness without a workspace was found.
  Scene scene = *props::scene(shape);
  const RigidTransform g = *group_element(group, shape.planar);
  return {std::move(scene), g};
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

namespace {

// Prefetch passes (batch.hpp). The first generates the cases (RapidCheck, as the real pass
// will) and keeps them; the others run the kept cases not yet answered in full, as far as their
// cached answers go. A pass stops starting cases once it has recorded its share of inputs: the
// first kFirstPassInputs, each pass after it twice as many as the one before, up to
// kMaxPendingPerPass (memory). A map that fails does so in its first cases as a rule, and the
// cases after a known failure are never asked for: the first passes find it before the whole
// check's inputs are evaluated, where an invariant map's cost grows only by the few extra
// flushes. Only the first kMaxPrefetchCases cases are kept and prefetched, and after
// kMaxPrefetchPasses the real pass evaluates what is left one input at a time. The answers, and
// so the verdicts, are the same whatever the passes' sizes: they only fill the cache.
constexpr std::size_t kFirstPassInputs = 64;
constexpr std::size_t kMaxPendingPerPass = std::size_t{1} << 15;
constexpr std::size_t kMaxPrefetchCases = std::size_t{1} << 14;
constexpr int kMaxPrefetchPasses = 64;

struct PrefetchedCases {
  std::vector<std::pair<Scene, RigidTransform>> cases;  ///< in RapidCheck's order
  std::vector<std::optional<CaseOutcome>> outcomes;     ///< each decided case's, when final
  bool complete = false;  ///< every case is kept and was answered in full
  bool failed = false;    ///< some case failed (or raised): the real pass must shrink it
};

PrefetchedCases run_prefetch_passes(const CaseFunction& run_case, Group group,
                                    const SceneShape& shape, const std::string& description,
                                    std::uint64_t seed, int cases) {
  PrefetchPasses passes;
  PrefetchedCases out;
  const std::size_t kept = std::min(static_cast<std::size_t>(cases), kMaxPrefetchCases);
  std::vector<char> done(kept, 0);
  out.outcomes.resize(kept);
  // The real pass stops at its first failing case and shrinks it one input at a time: cases
  // after the first one known to fail need no answers.
  std::size_t first_failure = kept;
  std::size_t share = kFirstPassInputs;
  auto run = [&](std::size_t k) {
    if (k >= first_failure || done[k] || passes.recorded() >= share) return;
    try {
      CaseOutcome outcome = run_case(out.cases[k].first, out.cases[k].second);
      if (!outcome.holds) first_failure = k;
      if (!outcome.provisional) out.outcomes[k] = std::move(outcome);
      done[k] = 1;
    } catch (const PendingEvaluation&) {
    } catch (...) {
      first_failure = std::min(first_failure, k);  // the real pass meets the error again
      done[k] = 1;
    }
  };
  passes.pass([&] {
    run_silently(
        [&] {
          // Beyond the kept cases, failing ends RapidCheck's run at once (a case that generated
          // nothing has nothing to shrink): generating them all would only cost time.
          if (out.cases.size() >= kept) RC_FAIL("the cases to prefetch are kept");
          out.cases.push_back(draw_case(shape, group));
          run(out.cases.size() - 1);
        },
        description, seed, cases);
  });
  int pass = 1;
  for (; pass < kMaxPrefetchPasses && passes.flush() > 0; ++pass) {
    share = std::min(2 * share, kMaxPendingPerPass);
    passes.pass([&] {
      for (std::size_t k = 0; k < out.cases.size(); ++k) run(k);
    });
  }
  out.failed = first_failure < kept;
  out.complete = kept == static_cast<std::size_t>(cases) && pass < kMaxPrefetchPasses &&
                 out.cases.size() == kept &&
                 std::all_of(done.begin(), done.end(), [](char d) { return d != 0; });
  return out;
}

// The same for CheckOptions::extra_cases, which run after the search: their inputs are asked for
// in passes of their own, so that a batched map answers them in a few calls, not one per input.
void prefetch_extra_cases(const CaseFunction& run_case,
                          const std::vector<std::pair<Scene, RigidTransform>>& extra_cases) {
  if (extra_cases.empty()) return;
  PrefetchPasses passes;
  std::vector<char> done(extra_cases.size(), 0);
  for (int pass = 0; pass < kMaxPrefetchPasses; ++pass) {
    passes.pass([&] {
      for (std::size_t k = 0; k < extra_cases.size(); ++k) {
        if (done[k]) continue;
        try {
          (void)run_case(extra_cases[k].first, extra_cases[k].second);
          done[k] = 1;
        } catch (const PendingEvaluation&) {
        } catch (...) {
          done[k] = 1;  // the real pass meets the error again
        }
      }
    });
    if (passes.flush() == 0) break;
  }
}

}  // namespace

Verdict run_check(const CaseFunction& run_case, Component component, Group group, Mode mode,
                  const CheckOptions& options, int cases, int shrink_budget,
                  const std::function<void()>& before_real_pass) {
  if (cases < 1)
    throw InvalidArgument("a check needs at least 1 case, got " + std::to_string(cases));
  if (!(options.relative_tolerance > 0.0) || !std::isfinite(options.relative_tolerance)) {
    throw InvalidArgument("relative_tolerance must be a positive number, got " +
                          std::to_string(options.relative_tolerance));
  }
  if (!(options.unit_roundoff > 0.0 && options.unit_roundoff < 1e-3)) {
    throw InvalidArgument(
        "unit_roundoff must be in (0, 1e-3) (2^-53 for double, 2^-24 for "
        "float32), got " +
        std::to_string(options.unit_roundoff));
  }
  const std::string description = to_string(component) + " under " + to_string(group);
  PrefetchedCases prefetched;
  if (options.prefetch) {
    prefetched =
        run_prefetch_passes(run_case, group, options.shape, description, options.seed, cases);
    prefetch_extra_cases(run_case, options.extra_cases);
    if (before_real_pass) before_real_pass();
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
  // A workspace that leaves the group no room is an error of the call, said before any case.
  // Recorded observations must lie inside it (recorded_case then finds a g for every group).
  if (shape.workspace && !shape.recorded) (void)shape.workspace->room_for(group);
  if (shape.workspace && shape.recorded) shape.recorded->require_inside(*shape.workspace);
  int shrink_evaluations = 0;
  int drawn = 0;  // cases drawn by the search
  // One case of the search: false when it failed (or raised: `error`).
  std::string case_label;  // set before each search_case: "case 12", "the extra case 1"
  auto search_case = [&](const Scene& scene, const RigidTransform& g, CaseOutcome& outcome,
                         bool decided = false) {
    try {
      if (!decided) outcome = run_case(scene, g);
    } catch (Error& e) {
      // The function under test could not answer here: say where, so that it can be replayed.
      e.add_context("raised in " + case_label + " of the " + to_string(component) + " (" +
                    to_string(mode) + ") check under " + to_string(group) + " (" +
                    to_string(view_of(shape)) + " view, seed " + std::to_string(options.seed) +
                    "), whose observation o has " + observation_summary(scene) +
                    " and g = " + pose_summary(g) +
                    ": the map was asked about o, g o or a scene a rounding step from them; the "
                    "same seed asks them again");
      error = std::current_exception();
      return false;
    } catch (...) {
      // Not a counterexample: the function under test could not answer (a handcentric::Error,
      // a Python exception, a missing module). The check stops and the caller sees it.
      error = std::current_exception();
      return false;
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
        if (outcome.holds && outcome.discontinuity) ++verdict.discontinuities;
      }
    }
    return outcome.holds;
  };
  const Verdict before_search = verdict;
  bool searched = false;
  if (prefetched.complete && !prefetched.failed) {
    // Every case held in the prefetch passes: the search is the kept cases in RapidCheck's
    // order, answered from the cache, with no shrinking to do (and no need to generate them a
    // third time). Should one fail after all (a map whose answers changed), RapidCheck reruns.
    searched = true;
    for (std::size_t k = 0; k < prefetched.cases.size(); ++k) {
      std::optional<CaseOutcome>& kept = prefetched.outcomes[k];
      CaseOutcome outcome = kept ? std::move(*kept) : CaseOutcome{};
      case_label = "case " + std::to_string(k + 1);
      if (!search_case(prefetched.cases[k].first, prefetched.cases[k].second, outcome,
                       kept.has_value())) {
        searched = false;
        break;
      }
    }
    if (error) std::rethrow_exception(error);
    if (!searched) {
      // A case failed in the real decision that the prefetch passes had only gathered for (an
      // in-distribution case's tests): RapidCheck searches again, to shrink it, from scratch.
      verdict = before_search;
      if (before_real_pass) before_real_pass();
    }
  }
  auto property = [&] {
    if (error) return;  // a broken function under test: let RapidCheck finish at once
    if (!searching && ++shrink_evaluations > (options.shrink ? shrink_budget : 0))
      return;  // budget spent: keep the witness
    const auto [scene, g] = draw_case(shape, group);
    CaseOutcome outcome;
    case_label = searching ? "case " + std::to_string(++drawn) : "a shrinking step";
    const bool holds = search_case(scene, g, outcome);
    // Failing the property ends RapidCheck's search at once (its shrinking then sees every
    // candidate pass, above), so a callable that raises costs one call whatever `cases` is.
    if (error) RC_FAIL("the function under test could not answer");
    if (!holds) {
      searching = false;
      verdict.witness = std::move(outcome.witness);  // the last failure is the shrunk one
      RC_FAIL("not invariant");
    }
  };
  if (!searched) run_silently(property, description, options.seed, cases);
  if (error) std::rethrow_exception(error);
  bool extra_witness = false;
  for (std::size_t k = 0; k < options.extra_cases.size() && !verdict.witness; ++k) {
    CaseOutcome outcome;
    case_label = "the extra case " + std::to_string(k + 1);
    const bool holds =
        search_case(options.extra_cases[k].first, options.extra_cases[k].second, outcome);
    if (error) std::rethrow_exception(error);
    if (!holds) {
      verdict.witness = std::move(outcome.witness);
      extra_witness = true;
    }
  }
  if (!verdict.witness && verdict.cases == verdict.discontinuities) {
    // Every case was near the identity (or sat on a discontinuity): nothing was shown either way.
    throw Error(to_string(component) + " under " + to_string(group) + " (" + to_string(mode) +
                ", " + to_string(verdict.view) + "): no verdict, " +
                (verdict.cases == 0
                     ? "all " + std::to_string(verdict.near_identity_cases) +
                           " cases had g near the identity, which can show no symmetry"
                     : "every far case sat on a discontinuity of the map") +
                "; run more cases (seed " + std::to_string(options.seed) + ")");
  }
  verdict.invariant = !verdict.witness.has_value();
  if (shape.workspace) verdict.note = shape.workspace->verdict_note();
  if (extra_witness) {
    verdict.note += std::string(verdict.note.empty() ? "" : "; ") +
                    "every drawn case held; the witness is the " +
                    (mode == Mode::pointwise ? "in-distribution" : "pointwise") +
                    " check's (the same group and view), run here as an extra case, where this "
                    "check fails too";
  }
  if (shape.recorded) {
    verdict.note += (verdict.note.empty() ? "" : "; ") + shape.recorded->verdict_note();
  }
  if (verdict.discontinuities > 0) {
    verdict.note += std::string(verdict.note.empty() ? "" : "; ") +
                    std::to_string(verdict.discontinuities) + " of " +
                    std::to_string(verdict.cases) +
                    " far cases sat on a discontinuity of the map (a bin edge, where inputs that "
                    "differ by rounding fall into neighbouring bins): the outputs differed there "
                    "but agreed with both scenes moved " +
                    format_number(off_case_scale(options.unit_roundoff)) +
                    " (1 + L) off the case; not counted as symmetry breaking";
  }
  return verdict;
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
  auto ask_all = [&sides](const std::vector<Scene>& scenes) {
    prefetch(scenes, [&sides](const Scene& s) {
      sides.ask(s);
      return 0;
    });
  };
  if (prefetching()) ask_all({scene, g * scene});
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
  if (prefetching()) {
    std::vector<Scene> asked;
    for (const auto& [side, p] : perturbed) asked.push_back(p);
    ask_all(asked);
  }
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
  if (prefetching()) {
    std::vector<Scene> asked;
    for (const Scene& s : nearby) {
      asked.push_back(s);
      asked.push_back(g * s);
    }
    ask_all(asked);
  }
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

Verdict check_invariance(const SceneFunction& f, Component component, Group group,
                         const CheckOptions& options) {
  auto run_case = [&f, &options](const Scene& scene, const RigidTransform& g) {
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
  };
  return detail::run_check(run_case, component, group, Mode::pointwise, options, options.cases,
                           kPointwiseShrinkBudget);
}

double recompute_error(const SceneFunction& f, const Witness& witness) {
  return detail::inf_distance(f(witness.scene), f(witness.g * witness.scene));
}

Verdict check_equivariance(const ChunkPolicy& policy, Group group, const CheckOptions& options) {
  const std::uint64_t noise_seed = options.noise_seed;
  auto run_case = [&policy, noise_seed, &options](const Scene& scene, const RigidTransform& g) {
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
    return detail::decide_pointwise(sides, scene, g, options);
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
