#pragma once
// handcentric.equivariance_profile: how far from equivariant
// (handcentric/props/checks/profile.hpp) a Python callable (a policy, or a representation's
// actions / observation function) or a built-in representation is, as a function of the
// transform's size.
#include <pybind11/pybind11.h>

#include <string>

#include "options.hpp"

namespace handcentric::python {

/// What a profile is of: exactly one of `policy` (a callable, with noise=), `representation` (a
/// built-in's name, REPRESENTATIONS or "actionflow", or a representation's actions function,
/// observation= its observation function) or the deprecated positional `either`, a callable taken
/// as a policy when noise= is given and as a representation otherwise.
struct Profiled {
  py::object either, policy, representation;
};

/// One profile of `handcentric audit --profile`'s JSON, as a dict. Throws InvalidArgument naming
/// the keyword to pass when `what` names no map, or more than one, or a policy without noise=;
/// warns (DeprecationWarning) on the positional form.
py::dict equivariance_profile(const Profiled& what, py::object group, const std::string& component,
                              py::handle noise, py::object observation, py::handle sizes,
                              int scenes, std::uint64_t seed, int samples, const std::string& view,
                              const Setup& setup);

}  // namespace handcentric::python
