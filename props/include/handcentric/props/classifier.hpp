#pragma once
// The classifier: for one representation (or flow target), which groups leave each component
// invariant, pointwise and in distribution (issue 3, item 4).
//
//   representation : actions, observation (pointwise); the input and the target of its
//                    rectified flow (eq. 5), pointwise and in distribution.
//   flow target    : its input and target, pointwise and in distribution.
// And what the paper says each built-in should give (App. A), to assert and to report against.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "handcentric/core/flow_target.hpp"
#include "handcentric/core/representation.hpp"
#include "handcentric/props/check.hpp"
#include "handcentric/props/distribution.hpp"
#include "handcentric/props/verdict.hpp"

namespace handcentric::props {

struct ClassifierOptions {
  CheckOptions check = eye_in_hand_options();  ///< eye-in-hand scenes: Theorem 1's setting
  DistributionOptions distribution = {};
  std::vector<Group> groups = all_groups();
  bool observation = true;   ///< check the observation (off for a plug-in that sends none)
  bool flow = true;          ///< check the rectified flow of a representation
  bool in_distribution = true;
};

struct Classification {
  std::string name;
  std::vector<Verdict> verdicts;  ///< one per (component, mode, group) checked
};

Classification classify_representation(std::shared_ptr<const Representation> representation,
                                       const ClassifierOptions& options = {});

Classification classify_flow_target(std::shared_ptr<const FlowTarget> target,
                                    const ClassifierOptions& options = {});

/// The groups whose verdict for (component, mode) held, in all_groups() order.
std::vector<Group> invariant_groups(const Classification& classification, Component component, Mode mode);

/// The verdict for (component, mode, group), or null when it was not checked.
const Verdict* find_verdict(const Classification& classification, Component component, Mode mode, Group group);

/// What App. A of the paper says (and what we assert) for a built-in: the groups that leave
/// (component, mode) invariant. Empty optional for a name or component the paper is silent on.
///   absolute: none. relative, relative_diff: actions and flow target under translation only,
///   observation (world proprioception) under none. hand_centric: everything under all five.
///   actionflow: pointwise none; flow target in distribution under rotation and c8 only.
std::optional<std::vector<Group>> paper_expectation(const std::string& name, Component component, Mode mode);

/// The cells of `classification` that differ from paper_expectation, one line each.
std::vector<std::string> mismatches_with_paper(const Classification& classification);

}  // namespace handcentric::props
