#pragma once
// outputs= of the Python module: a policy that returns a dict of outputs
// (outputs={"hand": "pose", "gripper": "invariant"}), each entry audited as a map of its own
// with the same observations, noise and seeds. What the kinds mean, and why an invariant entry
// u goes to the checks as the poses T_0 [I, u]: props/named_output.hpp, the one definition,
// which a policy plug-in's hello shares.
#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "arrays.hpp"
#include "handcentric/props/named_output.hpp"

namespace handcentric::python {

// One definition with the plug-ins' hello (props/named_output.hpp).
using props::NamedOutput;
using props::OutputKind;
using props::to_string;

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
