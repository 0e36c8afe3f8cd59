#pragma once
// Verdict: what one invariance / equivariance check concluded; docs/AUDIT.md says what each verdict
// means.
//
// A verdict says whether the check held, the largest error seen, how many cases it ran, the
// seed that replays it, and, when it did not hold, a witness shrunk by RapidCheck: the scene,
// the transform g and both outputs, f(scene) and f(g * scene) (for a policy: g * a(o) and
// a(g * o)). Replaying the same check with the same seed finds the same witness, bit for bit.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/scene.hpp"
#include "handcentric/props/group.hpp"
#include "handcentric/props/spelling.hpp"
#include "handcentric/props/view.hpp"

namespace handcentric::props {

/// What is checked: a representation's action vector or observation vector, a flow target's
/// network input or regression target, or an outer policy's world-frame chunk (equivariance).
enum class Component { actions, observation, flow_input, flow_target, policy };

/// pointwise: f(g * s) = f(s) for each case, with fixed noise eps and time t.
/// distribution: the law of f(s, eps), eps ~ N(0, I), equals the law of f(g * s, eps)
/// (distribution.hpp says how that is decided).
/// closed_loop: a stateful policy's executed poses over whole episodes (checks/closed_loop.hpp).
enum class Mode { pointwise, distribution, closed_loop };

/// How an in-distribution verdict was decided (pointwise checks compare values: `compared`).
///   exact_gaussian: the component is affine in eps on every case (checked), so its law is the
///                   Gaussian N(f(0), J J^T); the two laws were compared exactly, up to rounding.
///   partly_exact  : on some case only some coordinates were affine in eps (the same ones on
///                   both sides): their Gaussian laws were compared exactly, the other
///                   coordinates by the tests of energy_test; no case was tested whole.
///   energy_test   : some case had no coordinate compared exactly; the energy, paired mean and
///                   scale tests decided, and a "yes" only means no difference was found
///                   (detectable_shift, detectable_scale_ratio).
///   from_pointwise: a whole policy's law, from its pointwise "yes" at independent noise per
///                   case (policy_audit.hpp): nothing more was asked; it could miss what the
///                   pointwise "yes" could (detectable_frequency of its cases).
enum class Method { compared, exact_gaussian, energy_test, partly_exact, from_pointwise };

/// "actions", "observation", "flow_input", "flow_target", "policy".
std::string to_string(Component component);
/// "pointwise", "distribution", "closed_loop".
std::string to_string(Mode mode);
/// The views `names` name, each "eye_in_hand" or "third_person", or "all" for both; InvalidArgument
/// naming the option `option` ("views", "view") in the caller's spelling for an unknown name or
/// none.
std::vector<View> parse_views(const std::vector<std::string>& names, const std::string& option,
                              const Spelling& spelling = kCommandLineSpelling);
/// "compared", "exact_gaussian", "energy_test", "partly_exact", "from_pointwise".
std::string to_string(Method method);

/// A counterexample: the scene, g, and the two outputs compared.
struct Witness {
  Scene scene;
  RigidTransform g;
  Eigen::VectorXd
      before;  ///< f(scene)            (policy: g * a(o), flattened; exact law: its mean)
  Eigen::VectorXd
      after;           ///< f(g * scene)        (policy: a(g * o), flattened; exact law: its mean)
  double error = 0.0;  ///< |after - before|_inf; exact law: max(mean, covariance difference);
                       ///< energy test: the energy distance
  double tolerance = 0.0;     ///< what error had to stay below (tests: the case's level alpha)
  double length_scale = 0.0;  ///< L of the tolerance REL (1 + L): max(L(s), L(g s)), metres
  /// pointwise: the largest change of either side under a rounding-level perturbation of its
  /// inputs (check.hpp), 0 when the error was under the floor and it was not measured
  double rounding_response = 0.0;
  /// pointwise: the witness is a case moved slightly off the one drawn (check.hpp, step 3), the
  /// difference having persisted there: a symmetry breaking, not a bin edge
  bool off_case = false;
  double p_value = 1.0;  ///< tests: 3 x the smallest of their p-values (exact laws: 1)
  /// A pointwise witness of a policy or a flow: its noise is fixed_noise(noise dimension,
  /// noise_seed) (a seed-interface policy's: noise_seed itself), the noise of the case drawn
  /// (check.hpp, pointwise_noise_seed), for both sides; format_witness prints it.
  std::optional<std::uint64_t> noise_seed;
  std::string detail;  ///< exact law: which moment differs and by how much
};

struct Verdict {
  Component component = Component::actions;
  Group group = Group::se3;
  Mode mode = Mode::pointwise;
  View view = View::eye_in_hand;
  Method method = Method::compared;
  bool invariant = false;       ///< the check held on every case (and on at least one far case)
  double max_error = 0.0;       ///< largest error seen (before shrinking)
  double min_p_value = 1.0;     ///< distribution mode: smallest p-value seen
  int cases = 0;                ///< cases run with g far from the identity (tolerance.hpp)
  int near_identity_cases = 0;  ///< cases run with g near the identity (run, not counted)
  /// far cases where the two sides differed only at a discontinuity of the map (a bin edge):
  /// the difference vanished when the case was moved slightly off it (check.hpp)
  int discontinuities = 0;
  std::uint64_t seed = 0;
  double relative_tolerance = 0.0;  ///< the REL of the pointwise tolerance REL * (1 + L)
  /// In-distribution "yes" decided (partly) by tests: the smallest mean shift (Euclidean norm
  /// over the tested coordinates, in the component's units) the energy test detects with 90%
  /// power at its sample size and level (distribution.hpp), the largest over the cases.
  std::optional<double> detectable_shift;
  /// Likewise the smallest factor (> 1, either way) by which the standard deviation of one
  /// tested coordinate can change and the scale test detect it with 90% power.
  std::optional<double> detectable_scale_ratio;
  /// A remark the reader needs, e.g. that a failure would pass at float32 rounding.
  std::string note;
  std::optional<Witness> witness;  ///< present when !invariant
  /// The failing case as the search drew it, before shrinking (present when !invariant, unless
  /// the witness came from an extra case): a typical failure, where the witness is the smallest
  /// one, so the stronger evidence when another check runs it again (classifier.hpp,
  /// witness_cases).
  std::optional<std::pair<Scene, RigidTransform>> first_failure;
};

/// What a pointwise "yes" on `cases` far cases could have missed: the smallest frequency f of
/// violating (scene, g) draws that at least one of `cases` independent draws hits with 99%
/// probability, 1 - 0.01^(1/cases) (about 4.6 / cases). 1 when cases is 0.
double detectable_frequency(int cases);

/// One line: a pose's position and rotation vector at 4 significant digits.
std::string pose_summary(const RigidTransform& T);

/// One line: the hand now (T_0's position and rotation vector) and the sizes of an observation,
/// for an error that names where it happened (a witness prints the scene in full).
std::string observation_summary(const Scene& scene);

/// A compact, multi-line rendering of a witness (17 digits, so it reproduces the doubles).
std::string format_witness(const Witness& witness);

}  // namespace handcentric::props
