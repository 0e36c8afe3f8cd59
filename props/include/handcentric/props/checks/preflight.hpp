#pragma once
// Before any verdict on a whole policy: is it a function of its inputs?
//
// The pointwise check compares a(g o, n) with g a(o, n) and blames g for the difference. That is
// only right if asking a(o, n) again gives a(o, n) again, whatever was asked before and whatever
// else rides in the batch. Policies as public code ships them often do not: Diffusion Policy's
// predict_action draws torch.randn itself, LeRobot's ACT keeps an action queue or a temporal
// ensembler between calls, a batch norm left in train mode couples the rows of a batch. So the
// preflight asks a few observations A = (o_1..o_m) with the audit's fixed noise n:
//
//   repeat : A, then A again at once, then A a third time;
//   state  : other observations Q, three rows (o_1, q_1, o_2), A again, Q again;
//   batch  : A in another order, and A's first half alone (batched policies only).
//
// and compares each row with its first answer (chunk distance, within the preflight tolerance
// below). The outcomes:
//
//   every answer the same      the audit goes on; Preflight::repeatable.
//   the same after the repeat, different after Q, or different once and then the same (it
//                              remembers the previous call): StatefulPolicy, never a verdict.
//   different on every repeat, and the policy drew from a global random generator while it
//                              answered (a Python policy watches torch's, NumPy's and Python's):
//                              its own randomness. Not an error: the pointwise checks are left
//                              out (Preflight::note says why and how to pair the draws), the
//                              in-distribution ones need no pairing and stay.
//   different on every repeat, and no global draw seen (or the policy cannot tell): state that
//                              changes at every call (an action queue) or a generator of its
//                              own; StatefulPolicy, naming both and both fixes.
//   rows that change with the batch's order or size: BatchCoupling, never a verdict.
//
// What it can miss: state or coupling whose effect stays below the preflight tolerance
// (kPreflightRelativeTolerance (1 + L), above float32 rounding so that a float32 network's
// batch-dependent summation order is not called coupling), state that only shows after more
// calls than these, and coupling that the rows drawn here do not trigger.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/props/checks/check.hpp"

namespace handcentric::props {

class NoisyPolicy;  // policy_audit.hpp

/// REL of the preflight's tolerance REL (1 + L): 64 float32 units of rounding.
inline constexpr double kPreflightRelativeTolerance = 64 * kFloat32UnitRoundoff;

/// A policy whose answer to an observation depends on earlier calls (or that changes at every
/// call without drawing from a global generator): no verdict can be given on it as called.
class StatefulPolicy : public Error {
 public:
  using Error::Error;
};

/// A batched policy whose row for an observation depends on the other rows of its batch.
class BatchCoupling : public Error {
 public:
  using Error::Error;
};

/// A policy that draws its own random numbers, asked for pointwise verdicts only: without the
/// same draws on both sides no pointwise comparison can blame g (Preflight::note is the message).
class OwnRandomness : public Error {
 public:
  using Error::Error;
};

/// The fixes the preflight's messages name, in the caller's words.
struct PreflightSpelling {
  std::string rng = "serve_policy(..., rng=\"torch\") in the plug-in";
  std::string reset = "serve_policy(..., reset=policy.reset) in the plug-in";
  std::string noise = "read the audit's noise argument instead of drawing your own";
  std::string distribution = "its in-distribution verdicts stand: they need no pairing";
  std::string eval = "policy.eval() (no batch statistics)";
};

struct PreflightOptions {
  /// The scenes (shape, view's world points), seed, noise seed and tolerance of the audit.
  CheckOptions check = eye_in_hand_options();
  int observations = 4;  ///< m, the rows of A (and of Q)
  PreflightSpelling spelling;
};

struct Preflight {
  /// Every answer the same: pointwise verdicts can be given.
  bool repeatable = true;
  /// When not repeatable: one line, what differed, by how much, and the fixes.
  std::string note;
  /// The largest difference between two answers to the same input (m, chunk distance).
  double repeat_difference = 0.0;
  /// The global generators the policy drew from (empty: none, or it cannot tell).
  std::vector<std::string> draws;
  int calls = 0;  ///< act_fresh calls made
  int rows = 0;   ///< observations asked, repeats included
};

/// Runs the preflight (top of this file). Throws StatefulPolicy or BatchCoupling as described;
/// errors of the policy itself pass through.
Preflight preflight_policy(const NoisyPolicy& policy, const PreflightOptions& options = {});

}  // namespace handcentric::props
