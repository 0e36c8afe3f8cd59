#pragma once
// Does a representation keep the information in the action chunk? Invariance says nothing about
// it: a map that sends every chunk to zeros is invariant under every group. An action vector
// that two different chunks share (with the same observation) cannot be decoded, so a policy
// trained on it cannot act. The check (docs/AUDIT.md, "Degenerate maps"):
//
//   false: two scenes with the same history, points and extras but chunks apart by at least
//          1e-3 (m or rad) map to the same actions within the pointwise tolerance. Pairs are
//          made by changing one pose's translation, one pose's rotation, the whole chunk by a
//          rigid motion, or drawing another chunk; RapidCheck shrinks the pair (the witness).
//   true : no collision, and the representation decodes (built-ins; a plug-in that answers the
//          decode request) with decode(encode(s), s) = chunk on every case.
//   null : no collision, and no decoder to prove it (an undecided "maybe").
#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "handcentric/core/representation.hpp"
#include "handcentric/props/check.hpp"

namespace handcentric::props {

/// Two scenes that differ only in their chunks, and their (equal) action vectors.
struct Collision {
  Scene first, second;
  Eigen::VectorXd actions_first, actions_second;
  double chunk_distance = 0.0;   ///< max_k distance(T_k, T'_k)
  double action_distance = 0.0;  ///< |a - a'|_inf
  double tolerance = 0.0;        ///< what action_distance had to exceed
};

/// A scene whose decoded actions are not its chunk.
struct RoundTripFailure {
  Scene scene;
  std::vector<RigidTransform> decoded;
  double error = 0.0;  ///< max_k distance(decoded_k, T_k); infinite for a length mismatch
  double tolerance = 0.0;
};

struct Injectivity {
  std::optional<bool> injective;       ///< see the top of this file
  std::string how;                     ///< one sentence: how it was decided
  int cases = 0;                       ///< pairs tried
  int round_trips = 0;                 ///< decode(encode(s)) checked (0 without a decoder)
  std::optional<Collision> collision;  ///< when injective is false
  std::optional<RoundTripFailure> round_trip_failure;  ///< a decoder that does not invert
};

/// Runs options.cases pairs from options.seed on options.shape's scenes, with
/// options.relative_tolerance. Throws InvalidArgument for a null representation; rethrows a
/// handcentric::Error of the representation (a plug-in that stops answering).
Injectivity check_injectivity(std::shared_ptr<const Representation> representation,
                              const CheckOptions& options);

/// A multi-line rendering of a collision (17 digits) for the text report.
std::string format_collision(const Collision& collision);

}  // namespace handcentric::props
