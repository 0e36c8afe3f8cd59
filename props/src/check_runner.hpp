#pragma once
// Internal: the RapidCheck loop shared by the pointwise and the distribution checks. It
// tracks the largest error and the case counts of the search (not of the shrinking), keeps
// the last failing case (after shrinking: the shrunk witness), and rethrows a
// handcentric::Error raised by the function under test instead of shrinking it.
#include <functional>

#include "handcentric/props/check.hpp"

namespace handcentric::props::detail {

struct CaseOutcome {
  Witness witness;   ///< scene, g, outputs, error, tolerance, p-value of this case
  bool holds = true;
};

using CaseFunction = std::function<CaseOutcome(const Scene& scene, const RigidTransform& g)>;

/// Runs `cases` cases; after the first failure, RapidCheck shrinks for at most `shrink_budget`
/// evaluations (then every further candidate passes, and the last failure is the witness).
Verdict run_check(const CaseFunction& run_case, Component component, Group group, Mode mode,
                  const CheckOptions& options, int cases, int shrink_budget);

}  // namespace handcentric::props::detail
