#pragma once
// Does a representation keep the information in the action chunk? Invariance says nothing about
// it: a map that sends every chunk to zeros is invariant under every group. An action vector
// that two different chunks share (with the same observation) cannot be decoded, so a policy
// trained on it cannot act. Two searches look for such collisions (docs/AUDIT.md, "Degenerate
// maps"); a collision is two scenes with the same history, points and extras whose actions are
// equal within the pointwise tolerance REL (1 + L).
//
//   pairs     : chunks apart by at least 1e-3 (m or rad): one pose's translation or rotation
//               changed, the whole chunk moved by a rigid motion, or another chunk drawn. They
//               find gross losses (a dropped rotation); RapidCheck shrinks the pair (the witness).
//   resolution: on a few scenes, the chunk changed by a size drawn log-uniformly in each decade
//               of [1e-6, 1e-1]: one pose's translation or the whole chunk's (m), one pose's
//               rotation or the whole chunk's about its first pose (rad). A pair that collides
//               is regrown by factors of 10^(1/8) while it still collides. The resolution is the
//               largest change at which a pair collided: the map loses information below it (a
//               256-bin tokenizer over +-1 m: ~8 mm, its bin; 1 cm voxels: ~1 cm).
//
// Pairs the tolerance cannot tell apart are not tried: a map in the chunk's units moves its
// actions by at least 1/sqrt(3) of a change, so a change under 4 tolerances may collide in any
// map. Collisions below kSmallestLoss = 1e-4 (m or rad) are reported but decide nothing: a
// correct float32 map cannot tell apart changes below float's spacing (9.5e-7 m for
// coordinates of 8 to 16 m, 1.9e-6 m up to 32 m; the audit's scenes reach ~20 m). 1e-4 is 50
// times that, and 10 times below the 1 mm clearance of the tightest task here: a loss a task
// would feel is caught, rounding is not.
//
//   false: a pair (shrunk witness), or a resolution scan pair apart by kSmallestLoss or more
//          (the pair at the resolution is the witness, not shrunk), collided.
//   true : no such collision, and the representation decodes (built-ins; a plug-in that answers
//          the decode request) with decode(encode(s), s) = chunk on every case.
//   null : no such collision, and no decoder to prove it (an undecided "maybe").
#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "handcentric/core/representation.hpp"
#include "handcentric/props/checks/check.hpp"

namespace handcentric::props {

/// Two scenes that differ only in their chunks, and their (equal) action vectors.
struct Collision {
  Scene first, second;
  Eigen::VectorXd actions_first, actions_second;
  double chunk_distance = 0.0;   ///< max_k distance(T_k, T'_k)
  double action_distance = 0.0;  ///< |a - a'|_inf
  double tolerance = 0.0;        ///< what action_distance had to exceed
  std::string change;            ///< what changed, e.g. "one pose's translation moved by 6.2e-3 m"
  std::string search;            ///< which search found it: "pairs" or "resolution"
};

/// A scene whose decoded actions are not its chunk.
struct RoundTripFailure {
  Scene scene;
  std::vector<RigidTransform> decoded;
  double error = 0.0;  ///< max_k distance(decoded_k, T_k); infinite for a length mismatch
  double tolerance = 0.0;
};

/// Collisions found by the resolution scan in one decade [scale, 10 scale) of one unit.
struct ScaleCollisions {
  double scale = 0.0;  ///< the decade's lower end
  std::string unit;    ///< "m" (translations) or "rad" (rotations)
  int pairs = 0;       ///< pairs tried (those the tolerance can tell apart)
  int collisions = 0;  ///< of which collided
};

/// Changes below this (m or rad) that collide decide nothing: see the top of this file.
constexpr double kSmallestLoss = 1e-4;

struct Injectivity {
  std::optional<bool> injective;       ///< see the top of this file
  std::string how;                     ///< one sentence: how it was decided
  int cases = 0;                       ///< pairs tried by the pairs search
  int round_trips = 0;                 ///< decode(encode(s)) checked (0 without a decoder)
  std::optional<Collision> collision;  ///< when injective is false
  std::optional<RoundTripFailure> round_trip_failure;  ///< a decoder that does not invert
  /// The largest change at which a resolution pair collided, in resolution_unit: the metre one
  /// (a task's clearances are lengths) unless only rotations collided at kSmallestLoss or more.
  std::optional<double> resolution;
  std::string resolution_unit;                   ///< "m" or "rad" (empty without resolution)
  std::optional<double> translation_resolution;  ///< m
  std::optional<double> rotation_resolution;     ///< rad
  std::vector<ScaleCollisions> scales;           ///< per decade and unit
};

/// The resolution scan: sizes are drawn in each decade [d, 10 d) of `decades`, and regrown up to
/// 10 times the largest, on `scenes` scenes (0: max(10, cases / 8)). No decades: the pairs
/// search alone.
struct ResolutionOptions {
  std::vector<double> decades = {1e-6, 1e-5, 1e-4, 1e-3, 1e-2};
  int scenes = 0;
};

/// Runs options.cases pairs and the resolution scan from options.seed on options.shape's scenes,
/// with options.relative_tolerance. Throws InvalidArgument for a null representation, no cases
/// or a decade that is not positive and finite; rethrows a handcentric::Error of the
/// representation (a plug-in that stops answering).
Injectivity check_injectivity(std::shared_ptr<const Representation> representation,
                              const CheckOptions& options,
                              const ResolutionOptions& resolution = {});

/// "7.8e-3 m": a resolution in its unit, two digits.
std::string format_resolution(double value, const std::string& unit);

/// A multi-line rendering of a collision (17 digits) for the text report.
std::string format_collision(const Collision& collision);

}  // namespace handcentric::props
