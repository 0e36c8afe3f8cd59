#pragma once
// Verdict: what one invariance / equivariance check concluded (DESIGN.md "Check").
//
// A verdict says whether the check held, the largest error seen, how many cases it ran, the
// seed that replays it, and, when it did not hold, a witness shrunk by RapidCheck: the scene,
// the transform g and both outputs, f(scene) and f(g * scene) (for a policy: g * a(o) and
// a(g * o)). Replaying the same check with the same seed finds the same witness, bit for bit.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/scene.hpp"
#include "handcentric/props/group.hpp"

namespace handcentric::props {

/// What is checked: a representation's action vector or observation vector, a flow target's
/// network input or regression target, or an outer policy's world-frame chunk (equivariance).
enum class Component { actions, observation, flow_input, flow_target, policy };

/// pointwise: f(g * s) = f(s) for each case, with fixed noise eps and time t.
/// distribution: the samples of f(s, eps), eps ~ N(0, I) redrawn, and of f(g * s, eps) are
/// indistinguishable by a two-sample test (distribution.hpp).
enum class Mode { pointwise, distribution };

/// "actions", "observation", "flow_input", "flow_target", "policy".
std::string to_string(Component component);
/// "pointwise", "distribution".
std::string to_string(Mode mode);

/// A counterexample: the scene, g, and the two outputs compared.
struct Witness {
  Scene scene;
  RigidTransform g;
  Eigen::VectorXd before;  ///< f(scene)            (policy: g * a(o), flattened)
  Eigen::VectorXd after;   ///< f(g * scene)        (policy: a(g * o), flattened)
  double error = 0.0;      ///< pointwise: |after - before|_inf; distribution: energy distance
  double tolerance = 0.0;  ///< what error had to stay below (pointwise)
  double p_value = 1.0;    ///< distribution mode: the permutation p-value (else 1)
};

struct Verdict {
  Component component = Component::actions;
  Group group = Group::se3;
  Mode mode = Mode::pointwise;
  bool invariant = false;    ///< the check held on every case (and on at least one far case)
  double max_error = 0.0;    ///< largest error seen (before shrinking)
  double min_p_value = 1.0;  ///< distribution mode: smallest p-value seen
  int cases = 0;             ///< cases run with g far from the identity (tolerance.hpp)
  int near_identity_cases = 0;  ///< cases run with g near the identity (run, not counted)
  std::uint64_t seed = 0;
  std::optional<Witness> witness;  ///< present when !invariant
};

/// A compact, multi-line rendering of a witness (17 digits, so it reproduces the doubles).
std::string format_witness(const Witness& witness);

}  // namespace handcentric::props
