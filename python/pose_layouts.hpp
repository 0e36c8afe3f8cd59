#pragma once
// A policy's poses in the layout it speaks (action_format=, state_format=; core/pose_format.hpp
// defines each layout): the history and the extra poses it is given, encoded; the chunk it
// returns, decoded. With the default layout "matrix" every array is (..., 4, 4) as before.
#include <pybind11/numpy.h>

#include <string>
#include <vector>

#include "arrays.hpp"
#include "handcentric/core/pose_format.hpp"

namespace handcentric::python {

/// The hand's history of `scenes` in `format`: (H+1, 4, 4) or (H+1, w) for one scene, with a
/// leading batch axis when stacked.
py::array_t<double> history_in(const std::vector<const Scene*>& scenes, bool stacked,
                               const PoseFormat& format);

/// Extra pose `index` of `scenes` in `format`: (4, 4) or (w,), with a leading batch axis when
/// stacked.
py::array_t<double> extra_pose_in(const std::vector<const Scene*>& scenes, std::size_t index,
                                  bool stacked, const PoseFormat& format);

/// The chunks a policy returned: (K, 4, 4) or (K, w) for one scene; (B, K, 4, 4) or (B, K, w)
/// stacked, B = rows. `what` names the result. ShapeError for another shape (a pose vector of 6, 7
/// or 9 numbers returned without action_format= gets the keyword and the layouts of that width);
/// InvalidArgument naming the row and step for a vector that contradicts its layout.
std::vector<std::vector<RigidTransform>> chunks_from(py::handle result, std::size_t rows,
                                                     bool stacked, const PoseFormat& format,
                                                     const std::string& what);

}  // namespace handcentric::python

namespace handcentric::python {

/// handcentric.encode_pose: poses (..., 4, 4), validated, as vectors (..., w) in `format_name`
/// ("matrix": the poses themselves, (..., 4, 4)).
py::array_t<double> encode_pose_array(py::handle poses, const std::string& format_name);

/// handcentric.decode_pose: vectors (..., w) in `format_name` ("matrix": (..., 4, 4)) as poses
/// (..., 4, 4).
py::array_t<double> decode_pose_array(py::handle vectors, const std::string& format_name);

}  // namespace handcentric::python
