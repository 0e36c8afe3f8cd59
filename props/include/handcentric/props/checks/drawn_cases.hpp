#pragma once
// The cases a pointwise check draws, in its order, without deciding them: what a tool that
// looks inside the map under audit (handcentric.locate, python/locate.cpp) needs to ask the map
// about the audit's own (scene, g) pairs rather than about cases of a second generator.
#include <utility>
#include <vector>

#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/scene.hpp"
#include "handcentric/props/checks/check.hpp"
#include "handcentric/props/group.hpp"

namespace handcentric::props {

/// The first options.cases cases (scene, g) of a pointwise check of `group` with these options
/// (seed, shape, workspace, recorded observations), in RapidCheck's order: case k is the k-th
/// case check_invariance and check_policy_equivariance decide with the same options (the first
/// pass of their prefetch draws them the same way). Throws InvalidArgument for cases < 1.
std::vector<std::pair<Scene, RigidTransform>> drawn_cases(const CheckOptions& options, Group group);

}  // namespace handcentric::props
