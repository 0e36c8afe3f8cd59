#pragma once
// The gate of an audit (`handcentric audit --expect`): which symmetries the caller expects to
// hold, and the verdicts among those that do not. It decides the exit status of a CI job, so a
// front end (the command line, Python) asks it here instead of reading the verdicts itself; an
// item that matches no check that ran is an error, since an empty gate must not pass.
#include <optional>
#include <string>
#include <vector>

#include "handcentric/props/checks/classifier.hpp"
#include "handcentric/props/spelling.hpp"

namespace handcentric::props {

/// One expected symmetry: every component's checks under `group`, or only `component`'s.
struct ExpectedSymmetry {
  std::optional<Component> component;
  Group group;
};

/// Items "GROUP" (every component) or "COMPONENT:GROUP", e.g. "se3" or "actions:se3". Throws
/// InvalidArgument naming the item's unknown group or component and the valid names.
std::vector<ExpectedSymmetry> parse_expectations(const std::vector<std::string>& items,
                                                 const Spelling& spelling = kCommandLineSpelling);

/// A verdict an expectation asked to hold that does not, and the classification it is of.
struct GateFailure {
  std::string name;  ///< Classification::name
  Verdict verdict;
};

/// The verdicts of `results` that `expectations` ask to hold and do not, item by item in the
/// verdicts' order; none: the gate passes. Throws InvalidArgument, before anything is returned,
/// for an item that matches no verdict, naming its component when no verdict is of it (and one
/// that is) and else the groups and views to widen.
std::vector<GateFailure> gate_failures(const std::vector<Classification>& results,
                                       const std::vector<ExpectedSymmetry>& expectations,
                                       const Spelling& spelling = kCommandLineSpelling);

/// "expected invariance does not hold: NAME, COMPONENT (MODE, VIEW) under GROUP[; note: ...]"
/// (equivariance for a policy), then the witness when there is one; newline-terminated.
std::string gate_failure_text(const GateFailure& failure);

}  // namespace handcentric::props
