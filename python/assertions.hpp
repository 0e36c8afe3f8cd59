#pragma once
// The pytest assertions: assert_invariant and assert_equivariant raise AssertionError with every
// failing check's shrunk witness and how to replay it (e3nn's assert_equivariant, for whole
// policies and action representations).
#include <pybind11/pybind11.h>

#include <optional>
#include <string>

#include "options.hpp"

namespace handcentric::python {

void assert_invariant(py::object fn, const std::string& group, const std::string& component_name,
                      py::object observation, py::handle views, py::handle cases,
                      std::uint64_t seed, std::optional<double> tolerance,
                      const std::string& precision, py::handle extra_poses, py::handle scalars,
                      const Setup& setup);

void assert_equivariant(py::object policy, const std::string& group, const std::string& mode,
                        py::handle views, py::handle cases, std::uint64_t seed,
                        std::optional<double> tolerance, const std::string& precision,
                        py::handle noise_length, py::handle extra_poses, py::handle scalars,
                        py::handle rng, py::handle reset, py::handle action_format,
                        py::handle state_format, py::handle outputs, py::handle hands,
                        const Setup& setup);

}  // namespace handcentric::python
