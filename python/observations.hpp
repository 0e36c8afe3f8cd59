#pragma once
// observations=: the user's own recorded observations for an audit (props/observation/
// recorded.hpp): a path to a .jsonl or .npz file, or an iterable of dicts {"history": (H+1, 4, 4),
// "chunk", "hand_points", "world_points", "extra_poses": {name: (4, 4)}, "scalars": {name:
// number}, "held": {name: array}, "episode": integer} of NumPy arrays, lists or torch tensors;
// with several hands "history": {hand: (H+1, 4, 4)}. Held arrays keep float32 when given so (a
// policy's images), else become float64.
#include <pybind11/pybind11.h>

#include <memory>

#include "handcentric/props/observation/recorded.hpp"

namespace handcentric::python {

namespace py = pybind11;

/// None: nullptr. Throws InvalidArgument / ShapeError / DtypeError naming the observation (its
/// index), the part and the fix; at most kMaxObservations items are read.
std::shared_ptr<const props::RecordedObservations> observations_of(py::handle value);

/// The most observations an iterable may give (a larger dataset: sample it, or use a file).
inline constexpr long long kMaxObservations = 1000000;

}  // namespace handcentric::python
