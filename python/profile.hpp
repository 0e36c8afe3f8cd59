#pragma once
// handcentric.equivariance_profile: how far from equivariant (props/profile.hpp) a Python
// callable (a policy, or a representation's actions / observation function) or a built-in
// representation is, as a function of the transform's size.
#include <pybind11/pybind11.h>

#include <string>

#include "options.hpp"

namespace handcentric::python {

/// One profile of `handcentric audit --profile`'s JSON, as a dict. `what`: a built-in's name
/// (REPRESENTATIONS or "actionflow"), or a callable: a policy when noise= is given, else a
/// representation's actions function (observation= its observation function).
py::dict equivariance_profile(py::object what, const std::string& group,
                              const std::string& component, py::handle noise,
                              py::object observation, py::handle sizes, int scenes,
                              std::uint64_t seed, int samples, const std::string& view,
                              const Setup& setup);

}  // namespace handcentric::python
