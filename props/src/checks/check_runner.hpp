#pragma once
// Internal: the RapidCheck loop shared by the pointwise and the distribution checks. It
// tracks the largest error and the case counts of the search (not of the shrinking), keeps
// the last failing case (after shrinking: the shrunk witness), and rethrows a
// handcentric::Error raised by the function under test instead of shrinking it.
#include <functional>

#include <string>

#include "handcentric/props/checks/check.hpp"
#include "handcentric/props/checks/distribution.hpp"
#include "handcentric/props/checks/policy_audit.hpp"

namespace handcentric::props::detail {

/// What in-distribution cases saw, for the verdict: whether a case was tested whole (energy) or
/// split into exact and tested coordinates (partial), and, over the cases that reached the
/// tests, the largest number of coordinates tested and spread (for the detectable shift) and
/// the largest detectable scale ratio. One case's, or merged over a check's (merge()).
struct LawStatistics {
  bool any_energy = false;
  bool any_partial = false;
  int partial_cases = 0;
  std::string exact_coordinates;  ///< which coordinates the first partial case decided exactly
  Eigen::Index largest_dimension = 0;
  double largest_spread = 0.0;
  double largest_scale_ratio = 0.0;  ///< 0: no scale test ran
};

/// Folds one case's statistics into a check's: flags or-ed, counts added, largest values kept,
/// the first case's exact coordinates named.
void merge(LawStatistics& into, const LawStatistics& one);

struct CaseOutcome {
  Witness witness;  ///< scene, g, outputs, error, tolerance, p-value of this case
  bool holds = true;
  bool discontinuity = false;  ///< held only because the difference sat on a discontinuity
  /// An in-distribution case's statistics (run_check merges them over the cases it decides).
  LawStatistics statistics;
};

/// The two sides of a pointwise case, for the decision of check.hpp.
struct PointwiseSides {
  /// Sets witness.before, .after and .error for (scene, g * scene), g fixed by the caller.
  std::function<void(const Scene& scene, Witness& witness)> compare;
  /// How far one side's output moves between scenes a and b (the same side: f(a) against
  /// f(b), or a policy's chunks a(a) against a(b)).
  std::function<double(const Scene& a, const Scene& b)> response;
  /// Asks the map for one scene's output and drops it (a policy: its chunk at the case's noise),
  /// so that a prefetch pass (batch.hpp) records every scene a step needs at once.
  std::function<void(const Scene& scene)> ask;
};

/// Decides the case (scene, g) as the top of check.hpp says: the floor, the map's own
/// rounding, then off the case. The witness carries the scene that decided it.
CaseOutcome decide_pointwise(const PointwiseSides& sides, const Scene& scene,
                             const RigidTransform& g, const CheckOptions& options);

using CaseFunction = std::function<CaseOutcome(const Scene& scene, const RigidTransform& g)>;

/// Runs `cases` cases; after the first failure, RapidCheck shrinks for at most `shrink_budget`
/// evaluations (then every further candidate passes, and the last failure is the witness).
/// With options.prefetch, the prefetch passes of prefetch.hpp run first and keep the outcome of
/// each case they decide, so a case is decided once whether batched or not. `statistics`, when
/// given, receives the merged statistics of every case the verdict rests on (the search, the
/// shrinking, the extra cases), in the order an unbatched check decides them. `decide_extra_case`,
/// when given, decides options.extra_cases instead of `run_case` (an in-distribution check draws
/// more noise there).
Verdict run_check(const CaseFunction& run_case, Component component, Group group, Mode mode,
                  const CheckOptions& options, int cases, int shrink_budget,
                  LawStatistics* statistics = nullptr,
                  const CaseFunction& decide_extra_case = CaseFunction());

/// Two functions of the noise whose laws (eps ~ N(0, I)) a distribution check compares:
/// f(s, .) and f(g s, .) for a flow; g * a(o, .) and a(g o, .) for a policy.
struct NoisePair {
  std::function<Eigen::VectorXd(const Eigen::VectorXd&)> before, after;
  Eigen::Index noise_dimension = 0;
  std::string name;  ///< for errors: what changed length
};

/// One in-distribution case: exact Gaussian laws for the coordinates affine in eps on both
/// sides, the tests for the others (distribution.hpp). The witness's scene and g are left for the
/// caller; the outcome carries the case's statistics. `paired_draws`: the paired mean test's
/// shared draws when more than the other tests' (an extra case's).
CaseOutcome compare_laws(const NoisePair& pair, double tolerance, const CheckOptions& options,
                         const DistributionOptions& distribution, int paired_draws = 0);

/// The two functions of the noise to compare at a case: (scene, g scene, g) -> the pair.
using PairOfCase =
    std::function<NoisePair(const Scene& scene, const Scene& moved, const RigidTransform& g)>;

/// An in-distribution check: run_check over compare_laws of each case's pair, the extra cases
/// with extra_case_paired_draws, then finish_distribution_verdict.
Verdict run_distribution_check(const PairOfCase& pair_of, Component component, Group group,
                               const CheckOptions& options,
                               const DistributionOptions& distribution);

/// Sets the verdict's method and, for a "yes" by tests, its detectable shift and scale ratio.
void finish_distribution_verdict(Verdict& verdict, const LawStatistics& statistics,
                                 const DistributionOptions& distribution);

/// Throws InvalidArgument naming the bad values of `distribution`.
void require_distribution_options(const DistributionOptions& distribution);

/// Each pose as [p, r(R)], one after the other (a policy's witness).
Eigen::VectorXd flatten(const std::vector<RigidTransform>& chunk);

/// |a - b|_inf; infinite for different lengths, 0 for two empty vectors.
double inf_distance(const Eigen::VectorXd& a, const Eigen::VectorXd& b);

/// max_k distance(a_k, b_k) of two chunks; infinite for different lengths.
double chunk_distance(const std::vector<RigidTransform>& a, const std::vector<RigidTransform>& b);

/// g * T_k for each pose of a chunk.
std::vector<RigidTransform> moved_by(const RigidTransform& g,
                                     const std::vector<RigidTransform>& chunk);

/// Each pose as [p, R row-major]: 12 numbers on which g acts affinely (R -> R~ R, p -> R~ p + p~),
/// so a chunk affine in the noise stays affine after g.
Eigen::VectorXd flatten_affine(const std::vector<RigidTransform>& chunk);

/// policy.act(observation, noise), each pose checked: a chunk pose that is not a rigid transform
/// (a rotation block scaled by a bug) cannot be compared as one, so it stops the audit
/// (InvalidArgument naming the pose).
/// `pose_tolerance`: output_pose_tolerance of the audit's precision.
std::vector<RigidTransform> checked_act(const NoisyPolicy& policy, const Scene& observation,
                                        const Eigen::VectorXd& noise,
                                        double pose_tolerance = kOutputPoseTolerance);

/// One case as every check draws it, inside a RapidCheck property: (scene, g) from the recorded
/// observations, else inside the workspace, else from the generators (scene first, then g).
std::pair<Scene, RigidTransform> draw_case(const SceneShape& shape, Group group);

/// Runs a RapidCheck property (it calls RC_FAIL to fail) for `cases` cases from `seed`, printing
/// nothing: the caller records what it needs from inside the property.
void run_silently(const std::function<void()>& property, const std::string& description,
                  std::uint64_t seed, int cases);

/// For a batched map (`batched`), the questions of unit(0), ..., unit(units - 1) asked ahead: the
/// units run in prefetch passes (prefetch.hpp), each again until it runs to its end or raises,
/// with what they asked evaluated in batches between passes. What the units compute there is
/// dropped: the caller then runs them itself, in its order, and finds every answer cached.
/// Without `batched`, nothing.
void answer_units_ahead(bool batched, std::size_t units,
                        const std::function<void(std::size_t)>& unit);

/// The same for a RapidCheck property run as run_silently runs it; `reset` then undoes what the
/// property accumulated in its captures (after every pass).
void answer_property_ahead(bool batched, const std::function<void()>& property,
                           const std::function<void()>& reset, const std::string& description,
                           std::uint64_t seed, int cases);

}  // namespace handcentric::props::detail
