#pragma once
// How far from equivariant: a map's symmetry error as a function of the transform's size, beside
// the yes/no of the checks (check.hpp, distribution.hpp). What a reviewer compares between
// methods: does the error stay at rounding, grow with the angle, or vanish only on C8?
//
// The transform of size t (per scene i, a unit axis w_i and a unit direction u_i drawn once from
// the seed, so that each scene traces one curve):
//   translation : (I, t u_i), t in m                  (u_i in the plane z = 0 when planar)
//   rotation    : (exp(t w_i), 0), t in rad about the world origin
//   se2         : (R_z(t), t u_i), u_i in the plane: t rad and t m at once (the combined scale)
//   se3         : (exp(t w_i), t u_i): t rad and t m at once
//   c8          : (R_z(t), 0), t in rad; the default sizes are the multiples of 22.5 deg up to
//                 360 deg, so that the group's elements (multiples of 45 deg, in_group) alternate
//                 with the angles between them
// At each size, over the same seeded scenes s_i:
//   pointwise   : e = D / c, D the error of the audit's pointwise check at that g and c the
//                 chunk's scale.
//                 A representation component f (actions, observation, flow input or target at
//                 the fixed eps of check.hpp): D = |f(g s) - f(s)|_inf, c = max(|f(s)|_inf, 1e-3)
//                 (the output's own size, floored at 1 mm / 1 mrad so that a hand at rest does
//                 not divide by zero).
//                 A policy (eq. 4, the same noise n on both sides): D = max_k d((g a(o, n))_k,
//                 a(g o, n)_k), d(A, B) = |R_A - R_B|_F + |p_A - p_B|_2 (core's distance), and
//                 c = max(max_k d(a(o, n)_k, T_0), 1e-3): how far the chunk reaches from the hand
//                 now, in the same distance.
//   distribution: (flow targets and policies; a deterministic component has none) a distance
//                 between the law of the left side and the law of the right side, eps ~ N(0, I),
//                 divided by c:
//                 exact_gaussian where both sides are affine in eps (affine_law.hpp's
//                 affine_law; every rectified flow, ActionFlow's target): the larger of
//                 |mean_a - mean_b|_inf and |Sigma_a - Sigma_b|_inf / (2 s), s the largest
//                 standard deviation of either law (the change of a standard deviation of size
//                 s the covariances' difference makes, to first order), both from
//                 law_difference, in the output's units;
//                 else energy_distance: the energy distance (Szekely & Rizzo, 2 E|X - Y| -
//                 E|X - X'| - E|Y - Y'|, in the output's units) between `samples` draws of
//                 each side taken with the same eps (common random numbers: 0 when the map is
//                 pointwise equivariant). Two samples of one law are not at 0 apart: the
//                 profile's `floor` is the median over the scenes of the same statistic between
//                 two independent samples of the left side, the level below which a difference
//                 in law cannot be told from sampling.
//   slope at the identity: the Lie derivative of Gruver et al. (2023), "The Lie Derivative for
//                 Measuring Learned Equivariance": |L_X f(s)| = |d/dt f(exp(tX) s)|_{t=0}| for a
//                 component, |d/dt exp(-tX) a(exp(tX) o, n)|_{t=0}| for a policy, X the scene's
//                 unit generator (the size-1 direction above; for c8 the rotation about z, the
//                 continuous group C8 sits in). Central difference at t = +-h:
//                 D(f(g_h s), f(g_-h s)) / (2 h c), D as for the pointwise error.
// Each statistic is reported as its median and its maximum over the scenes. Deterministic given
// the seed: the scenes, axes and noise come from it alone.
#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "handcentric/core/flow_target.hpp"
#include "handcentric/props/checks/check.hpp"
#include "handcentric/props/checks/policy_audit.hpp"

namespace handcentric::props {

/// The transform of size `size` along a scene's unit `axis` (rotations) and unit `direction`
/// (translations), as the top of this file says, its rotation about `centre` (a world point:
/// g = (R, centre - R centre + translation)); the groups of group.hpp turn about the origin.
RigidTransform profile_transform(Group group, double size, const Eigen::Vector3d& axis,
                                 const Eigen::Vector3d& direction,
                                 const Eigen::Vector3d& centre = Eigen::Vector3d::Zero());

/// The unit of a group's sizes: "m", "rad", or "rad and m" (se2, se3).
std::string profile_unit(Group group);

/// The default sizes: translation 1e-3 to 10 m, rotation, se2 and se3 1e-3 to 3 (a 1-3 log grid),
/// c8 k * 22.5 deg for k = 1..16.
std::vector<double> default_profile_sizes(Group group);

/// True when the transform of this size is in the group itself: for c8 a multiple of 45 deg
/// (within 1e-9 rad), else always.
bool profile_size_in_group(Group group, double size);

struct ProfileOptions {
  std::vector<double> sizes;  ///< empty: default_profile_sizes(group); each finite and > 0
  int scenes = 16;            ///< scenes per size, 1 to 10^4
  std::uint64_t seed = 1;     ///< the scenes, axes and directions
  SceneShape shape = eye_in_hand_shape();
  std::uint64_t noise_seed = 1;  ///< the fixed eps or n of the pointwise error, and the draws
  double flow_time = 0.5;        ///< t of a flow target
  int samples = 32;              ///< draws per side of the energy distance, 2 to 10^4
  double slope_step = 1e-3;      ///< h of the central difference, in (0, 0.1]
  /// The point rotations turn about (finite; e.g. a C8 model's symmetry centre, which need not
  /// be the world origin). Translations are unchanged.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  /// Ask a batched map (batch.hpp) for each size's inputs at once before computing: the same
  /// numbers, fewer calls.
  bool prefetch = false;
};

/// `options` on the scenes the audit's checks of `view` draw (with_view(classifier.check, view),
/// classifier.hpp): their shape (a plug-in's extra poses and scalars, fixed sizes), prefetch,
/// seed and noise seed; sizes, scene count and the rest kept. The command line and Python set a
/// profile up through the audit's options so that both draw the scenes an audit would.
ProfileOptions with_audit_setup(ProfileOptions options, const ClassifierOptions& classifier,
                                View view);

/// A profile's scene i with its unit rotation axis and unit translation direction (z and a
/// direction in the plane for planar shapes), as profile_transform takes them.
struct ProfileCase {
  Scene scene;
  Eigen::Vector3d axis, direction;
};

/// The scenes a profile with these options runs on, in order: options.scenes scenes of
/// options.shape from RapidCheck seed options.seed, and the axes and directions from the same
/// seed. Throws InvalidArgument for bad options.
std::vector<ProfileCase> profile_cases(const ProfileOptions& options);

/// The median and the maximum of a statistic over the scenes.
struct Spread {
  double median = 0.0;
  double max = 0.0;
};

struct ProfilePoint {
  double size = 0.0;
  bool in_group = true;  ///< profile_size_in_group
  Spread pointwise;
  std::optional<Spread> distribution;  ///< none for a deterministic component
};

struct Profile {
  std::string name;  ///< the map, e.g. "hand_centric" or "model hc.model (flow/hand_centric)"
  Component component = Component::actions;
  Group group = Group::se3;
  View view = View::eye_in_hand;
  std::vector<ProfilePoint> points;
  Spread slope;  ///< the Lie derivative's norm at the identity
  /// "" (no distribution), "exact_gaussian", "energy_distance", or "exact_gaussian and
  /// energy_distance" (some scenes each way)
  std::string distribution_method;
  std::optional<double> distribution_floor;  ///< energy_distance only (see the top)
  int scenes = 0;
  std::uint64_t seed = 0;
  double slope_step = 0.0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
};

/// The profile of a deterministic function of a scene (a representation's actions or
/// observation). Throws InvalidArgument for bad options; rethrows what f throws.
Profile profile_function(const SceneFunction& f, const std::string& name, Component component,
                         Group group, const ProfileOptions& options = {});

/// The profile of a flow target's network input (Component::flow_input) or regression target
/// (flow_target): pointwise at the fixed eps, and in distribution.
Profile profile_flow(std::shared_ptr<const FlowTarget> target, Component component, Group group,
                     const ProfileOptions& options = {});

/// The profile of a whole policy (eq. 4), pointwise and in distribution.
Profile profile_policy(const NoisyPolicy& policy, Group group, const ProfileOptions& options = {});

/// {"unit": ..., "profiles": [{"name", "component", "group", "view", "unit", "scenes", "seed",
/// "sizes", "in_group", "pointwise": {"median", "max"}, "distribution": null or {"method",
/// "median", "max", "floor"}, "lie_derivative": {"median", "max", "step", "method"}}],
/// "normalization": one sentence}; the lists run over the sizes.
std::string profile_json(const std::vector<Profile>& profiles);

}  // namespace handcentric::props
