#pragma once
// A policy that returns a dict of outputs (outputs={"hand": "pose", "gripper": "invariant"}):
// each entry is audited as a map of its own, with the same observations, noise and seeds.
//   pose       a chunk of world-frame poses (action_format= applies), which must move with g:
//              a(g o) = g a(o);
//   invariant  numbers of any shape per observation (a gripper width per step, a terminate
//              flag), which must not change: u(g o) = u(o).
// An invariant entry u is handed to the checks as the poses T_0 [I, u_3j..3j+2] (its numbers
// three at a time as positions in the hand's frame at T_0, the last padded with zeros): g moves
// T_0 to g T_0, so these poses move with g exactly when u is invariant, and a change of u by d
// moves them by d. Every check of the equivariance audit then decides invariance as it is, in
// both modes, with the output's own units as its errors.
#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "arrays.hpp"

namespace handcentric::python {

enum class OutputKind { pose, invariant };

struct NamedOutput {
  std::string name;
  OutputKind kind = OutputKind::pose;
};

std::string to_string(OutputKind kind);

/// outputs= checked: None gives none (the policy returns its chunk alone); else a dict
/// {name: "pose" or "invariant"}, with at least one pose entry when `need_pose` (not with hands=,
/// which adds one per hand), refused in one line naming the value otherwise.
std::vector<NamedOutput> outputs_from(py::handle outputs, bool need_pose);

/// The entry `name` of a policy's result `result`, which must be a dict whose keys are exactly
/// the names of `outputs` (a key outputs= does not name, or a name the dict lacks, is refused
/// naming it and the fix). `what` names the result.
py::object output_entry(py::handle result, const std::vector<NamedOutput>& outputs,
                        const std::string& name, const std::string& what);

/// An invariant entry as poses (see the top of this file), one chunk per observation: one
/// observation's numbers when not stacked, (B, ...) when stacked.
std::vector<std::vector<RigidTransform>> invariant_as_poses(
    py::handle entry, const std::vector<const Scene*>& observations, bool stacked,
    const std::string& what);

}  // namespace handcentric::python
