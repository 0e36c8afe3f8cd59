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

/// |a - b|_inf; infinite for different lengths, 0 for two empty vectors.
double inf_distance(const Eigen::VectorXd& a, const Eigen::VectorXd& b);

/// max_k distance(a_k, b_k) of two chunks; infinite for different lengths.
double chunk_distance(const std::vector<RigidTransform>& a, const std::vector<RigidTransform>& b);

/// Runs a RapidCheck property (it calls RC_FAIL to fail) for `cases` cases from `seed`, printing
/// nothing: the caller records what it needs from inside the property.
void run_silently(const std::function<void()>& property, const std::string& description, std::uint64_t seed,
                  int cases);

}  // namespace handcentric::props::detail
