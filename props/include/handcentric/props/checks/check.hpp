#pragma once
// Pointwise checks: invariance of any function of a scene (a representation's actions or
// observation, a flow target's input or regression target at fixed eps and t), and equivariance
// of an outer policy (eq. 4). Each runs RapidCheck on generated (scene, g) pairs, g from a
// group (generators.hpp, edge cases included), and returns a Verdict (verdict.hpp) with a
// shrunk witness when the check fails. Tolerances and the near-identity rule: tolerance.hpp.
//
// How one case (s, g) is decided, with e the error between the two sides:
//   1. e <= REL (1 + L), the floor (`relative_tolerance`): holds.
//   2. else the map's own rounding: r = the largest change of either side's output when its
//      scene's inputs move by a few units of rounding (rounding_perturbation, two draws per
//      side). e <= 8 r with r <= sqrt(u) (1 + L): holds (the difference is the map's rounding).
//   3. else the case is moved slightly off, s' = nearby_scene(s) (three draws), and g s' is
//      compared with s'. If the difference vanishes on all three (below the floor or 8 r), the
//      case sat on a discontinuity of the map, a bin edge where inputs 1e-15 apart fall into
//      neighbouring bins: it holds and is counted (Verdict::discontinuities). If it persists on
//      any, the case fails, and its witness is that off-edge scene s'.
// A genuine symmetry breaking persists off the case and is far above the map's rounding, so it
// fails at step 3; rounding and bin edges do not.
//
// Errors thrown by the function under test (a handcentric::Error, a Python exception, a plug-in
// that stops answering) are not counterexamples: the check stops and rethrows them. A check
// that ran no case with g far from the identity throws: a verdict needs evidence.
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

#include "handcentric/core/chunk_policy.hpp"
#include "handcentric/core/flow_target.hpp"
#include "handcentric/core/representation.hpp"
#include "handcentric/props/observation/generators.hpp"
#include "handcentric/props/noisy_policy.hpp"
#include "handcentric/props/run.hpp"
#include "handcentric/props/tolerance.hpp"
#include "handcentric/props/verdict.hpp"

namespace handcentric::props {

struct CheckOptions {
  int cases = kDefaultCases;          ///< RapidCheck cases per check (near-identity ones included)
  std::uint64_t seed = kDefaultSeed;  ///< RapidCheck seed: same seed, same cases, same witness
  SceneShape shape = {};              ///< scene sizes
  std::uint64_t noise_seed = 1;       ///< the fixed eps of pointwise flow checks
  double flow_time = 0.5;             ///< the fixed t of flow checks
  /// The pointwise tolerance is relative_tolerance * (1 + L) (tolerance.hpp). 1e-9 suits double
  /// arithmetic; a policy computed in float needs ~1e-4.
  double relative_tolerance = kRelativeTolerance;
  /// The unit roundoff of the arithmetic the map is computed in (2^-53 double, 2^-24 float32):
  /// how far rounding_perturbation moves the inputs when a case is above the floor.
  double unit_roundoff = kFloat64UnitRoundoff;
  /// The unit roundoff of the numbers the policy returns, which sets how far its output poses
  /// may be from rigid transforms (output_pose_tolerance); 0: unit_roundoff. A 16-bit policy
  /// returns 16-bit poses while its world-frame arithmetic, what the rounding probe models, is
  /// float32 (audit.hpp, Precision).
  double output_unit_roundoff = 0.0;
  /// Scenes moved slightly off a case above the floor and the map's rounding, to tell a bin
  /// edge from a symmetry breaking (step 3 above). 0 decides on steps 1 and 2 alone: then every
  /// such case fails, bin edges included (a test's planted fault).
  int off_case_draws = 3;
  /// Shrink a failing case to a small witness (false: keep the first failure as it was found,
  /// for a re-check that only needs the yes or no).
  bool shrink = true;
  /// Run the prefetch passes of batch.hpp before the check, so that a batched map
  /// (BatchedPolicy, BatchedRepresentation) is asked for many inputs at once. The verdict is the
  /// same; for a map that is not batched it only costs time.
  bool prefetch = false;
  /// Cases run after the drawn ones, and counted with them: the classifiers hand an
  /// in-distribution check the witness of the pointwise check of the same component, group and
  /// view, a scene where the values already differ, so the law most likely differs there too.
  /// Without it, a map that breaks the symmetry on a small part of the scenes (a camera fixed in
  /// the world that sees the scene in one case of 65) could fail pointwise and still pass the
  /// few in-distribution cases by luck. A witness found here is not shrunk (it already was).
  std::vector<std::pair<Scene, RigidTransform>> extra_cases;
};

/// Eye-in-hand scenes (no world points): Theorem 1's assumption.
SceneShape eye_in_hand_shape();

/// Third-person scenes: one to eight world points (up to 10 m out) that move with g, beside up
/// to three eye-in-hand points: a fixed camera's view, outside Theorem 1's assumption.
SceneShape third_person_shape();

/// eye_in_hand_shape() or third_person_shape().
SceneShape shape_for(View view);

/// The view a shape's scenes show: third_person when they may carry world points.
View view_of(const SceneShape& shape);

/// CheckOptions with shape_for(view).
CheckOptions options_for(View view);

/// CheckOptions with eye_in_hand_shape().
CheckOptions eye_in_hand_options();

/// A vector-valued function of a scene, the thing whose invariance is checked.
using SceneFunction = std::function<Eigen::VectorXd(const Scene&)>;

SceneFunction actions_of(std::shared_ptr<const Representation> representation);
SceneFunction observation_of(std::shared_ptr<const Representation> representation);

/// The flow target's network input (or regression target) at time t and a fixed eps: the
/// first noise_dimension(scene) standard normals of mt19937_64(noise_seed). The same eps is
/// used for s and g * s, so this is the pointwise question of App. A (eqs. 11, 16, 23, 29) at
/// one eps (the profile's; the audit asks each case at its own: check_flow_invariance).
SceneFunction flow_input_of(std::shared_ptr<const FlowTarget> target, std::uint64_t noise_seed,
                            double t);
SceneFunction flow_target_of(std::shared_ptr<const FlowTarget> target, std::uint64_t noise_seed,
                             double t);

/// The noise seed of the pointwise case (scene, g) under `options`: from the scene alone, which
/// no other case of a check shares (so the checks of other groups ask o with the same noise,
/// one row for all), and from g too when the scenes are recorded observations, which the cases
/// of a check share (each case its own noise still). case_noise_seed of noisy_policy.hpp. The
/// pointwise checks of policies and of flows draw each case's noise from it.
std::uint64_t pointwise_noise_seed(const CheckOptions& options, const Scene& scene,
                                   const RigidTransform& g);

/// A flow's `component` (flow_input or flow_target) pointwise: f(g s, eps, t) = f(s, eps, t)
/// with t = options.flow_time and eps = fixed_noise(noise_dimension(s), pointwise_noise_seed(
/// options, s, g)), its own draw for each case, the same on both sides (App. A's question, eqs.
/// 11, 16, 23, 29, asked at many eps). The witness carries its noise_seed.
Verdict check_flow_invariance(std::shared_ptr<const FlowTarget> target, Component component,
                              Group group, const CheckOptions& options = {});

/// f(g * s) = f(s) within pointwise_tolerance for g in `group`. `component` only labels the
/// verdict.
Verdict check_invariance(const SceneFunction& f, Component component, Group group,
                         const CheckOptions& options = {});

/// |f(g * s) - f(s)|_inf recomputed from a witness (a test re-derives the counterexample).
double recompute_error(const SceneFunction& f, const Witness& witness);

/// eq. (4): policy.act(g * o, s) = g * policy.act(o, s) within pointwise_tolerance, for the
/// observations generated with options.shape, s = pointwise_noise_seed(options, o, g) for each
/// case (the witness's noise_seed). The witness's before/after are g * a(o) and a(g * o), each
/// pose flattened to [p, r(R)].
Verdict check_equivariance(const ChunkPolicy& policy, Group group,
                           const CheckOptions& options = {});

/// max_k distance(a(g * o)_k, (g * a(o))_k) recomputed from a witness, at its noise_seed (a
/// witness of check_equivariance has one), else at `noise_seed`.
double recompute_equivariance_error(const ChunkPolicy& policy, const Witness& witness,
                                    std::uint64_t noise_seed);

}  // namespace handcentric::props
