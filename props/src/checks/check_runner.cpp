#include "check_runner.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <iostream>
#include <limits>
#include <optional>
#include <random>
#include <sstream>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/props/observation/recorded.hpp"
#include "handcentric/props/prefetch.hpp"
#include "handcentric/props/tolerance.hpp"
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
      out.outcomes[k] = std::move(outcome);
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

}  // namespace

void answer_units_ahead(bool batched, std::size_t units,
                        const std::function<void(std::size_t)>& unit) {
  if (!batched || units == 0) return;
  PrefetchPasses passes;
  std::vector<char> done(units, 0);
  for (int pass = 0; pass < kMaxPrefetchPasses; ++pass) {
    passes.pass([&] {
      for (std::size_t k = 0; k < units; ++k) {
        if (done[k]) continue;
        try {
          unit(k);
          done[k] = 1;
        } catch (const PendingEvaluation&) {
          // stopped at a question this pass recorded: the next pass goes a question further
        } catch (...) {
          done[k] = 1;  // the caller's own run meets the error again
        }
      }
    });
    if (passes.flush() == 0) break;
  }
}

void answer_property_ahead(bool batched, const std::function<void()>& property,
                           const std::function<void()>& reset, const std::string& description,
                           std::uint64_t seed, int cases) {
  if (!batched) return;
  // A case that stops at an unanswered question passes, so RapidCheck draws the next one.
  const auto stopping = [&property] {
    try {
      property();
    } catch (const PendingEvaluation&) {
    }
  };
  PrefetchPasses passes;
  for (int pass = 0; pass < kMaxPrefetchPasses; ++pass) {
    passes.pass([&] { run_silently(stopping, description, seed, cases); });
    reset();
    if (passes.flush() == 0) return;
  }
}

namespace {

// An in-distribution case decided as a pointwise one is at its step 3 (check.hpp): laws that
// differ at the case drawn but agree with the case moved slightly off it (the same g, the same
// noise draws) differ by a discontinuity of the map, a bin edge (a hand at rest, whose
// hand-frame angles are exactly 0, binned by floor), not by g. The case then holds and is
// counted; a difference that persists on any of the moved cases fails there, with that scene as
// the witness. The moved scenes come from a generator seeded the same for every call, so a
// prefetch pass asks for the scenes the real pass decides.
CaseOutcome decided_off_the_case(const CaseFunction& decide_case, const Scene& scene,
                                 const RigidTransform& g, const CheckOptions& options) {
  CaseOutcome outcome = decide_case(scene, g);
  if (outcome.holds || options.off_case_draws < 1) return outcome;
  std::mt19937_64 rng(options.seed ^ 0xbb67ae8584caa73bULL);
  const double eta = off_case_scale(options.unit_roundoff);
  for (int d = 0; d < options.off_case_draws; ++d) {
    CaseOutcome off = decide_case(nearby_scene(scene, eta, rng, options.shape.planar), g);
    if (!off.holds) {
      off.witness.off_case = true;
      return off;
    }
    merge(outcome.statistics, off.statistics);
  }
  outcome.holds = true;
  outcome.discontinuity = true;
  return outcome;
}

}  // namespace

Verdict run_check(const CaseFunction& decide_case, Component component, Group group, Mode mode,
                  const CheckOptions& options, int cases, int shrink_budget,
                  LawStatistics* statistics, const CaseFunction& decide_extra_case) {
  // In distribution, a case is decided off the case too (decided_off_the_case, above).
  auto with_rules = [mode, &options](const CaseFunction& decide) {
    if (mode != Mode::distribution) return decide;
    return CaseFunction([decide, &options](const Scene& scene, const RigidTransform& g) {
      return decided_off_the_case(decide, scene, g, options);
    });
  };
  const CaseFunction run_case = with_rules(decide_case);
  const CaseFunction run_extra_case =
      with_rules(decide_extra_case ? decide_extra_case : decide_case);
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
    // The extra cases run after the search: their inputs are asked for in passes of their own,
    // so that a batched map answers them in a few calls, not one per input.
    const auto& extra = options.extra_cases;
    answer_units_ahead(true, extra.size(), [&](std::size_t k) {
      (void)run_extra_case(extra[k].first, extra[k].second);
    });
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
                         bool decided = false, const CaseFunction* decide = nullptr) {
    try {
      if (!decided) outcome = (decide ? *decide : run_case)(scene, g);
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
    if (statistics) merge(*statistics, outcome.statistics);
    if (searching) {
      const double e = std::isnan(outcome.witness.error) ? std::numeric_limits<double>::infinity()
                                                         : outcome.witness.error;
      // The number beside a verdict leaves out the cases that sat on a discontinuity (their
      // count is in the note): a "yes" beside an error of a whole bin would read as a breaking.
      if (!(outcome.holds && outcome.discontinuity))
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
      if (statistics) *statistics = {};
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
      if (searching) verdict.first_failure = {outcome.witness.scene, outcome.witness.g};
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
    const bool holds = search_case(options.extra_cases[k].first, options.extra_cases[k].second,
                                   outcome, false, &run_extra_case);
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

}  // namespace detail
}  // namespace handcentric::props
