#pragma once
// Conversions between the library's values and the arrays a Python callable takes and returns:
// NumPy arrays, or torch tensors when the caller asks for them (ArrayKind::torch). Results are
// read whatever they are: NumPy arrays, lists, and torch tensors on any device, with or without
// grad (detached and copied to the CPU; the audit never backpropagates). Errors name the value,
// its shape or dtype, and what was expected.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/scene.hpp"

namespace handcentric::python {

namespace py = pybind11;

/// A Python exception raised inside a callable under audit, carried through the C++ checks (a
/// handcentric::Error, so that the checks stop and rethrow it) and restored, traceback included,
/// when the module's function returns.
class PythonCallError : public Error {
 public:
  explicit PythonCallError(py::error_already_set error)
      : Error("a Python callable raised an exception"),
        error(std::make_shared<py::error_already_set>(std::move(error))) {}
  std::shared_ptr<py::error_already_set> error;
};

/// An array of the wrong shape (argument or result): Python ValueError subclass ShapeError.
class ShapeError : public InvalidArgument {
 public:
  using InvalidArgument::InvalidArgument;
};

/// Something that is not an array of real numbers: Python TypeError.
class DtypeError : public InvalidArgument {
 public:
  using InvalidArgument::InvalidArgument;
};

/// "(2, 4, 4)".
std::string shape_of(const py::array& a);

/// The name of value's type.
std::string type_name(py::handle value);

using RealArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// `value` as a C-contiguous float64 array. Torch tensors are detached and moved to the CPU
/// first; DtypeError for anything that is not real numbers.
RealArray real_array(py::handle value, const std::string& what);

/// InvalidArgument at the first non-finite entry.
void require_finite(const double* data, py::ssize_t n, const std::string& what);

Eigen::VectorXd vector_from(py::handle value, const std::string& what);
Eigen::Vector3d vector3_from(py::handle value, const std::string& what);
Eigen::Matrix4d matrix4_from(py::handle value, const std::string& what);
std::vector<Eigen::Vector3d> points_from(py::handle value, const std::string& what);

/// A stack of poses (n, 4, 4), n >= 1; each validated as a rigid transform unless `loose`, where
/// the rotation block is taken as it is (a float32 policy's is orthonormal to ~1e-7 only, as for
/// the --policy-exec pipe) and only the last row is checked (to 1e-6).
std::vector<RigidTransform> poses_from(py::handle value, const std::string& what,
                                       bool loose = false, const char* expected = "(n, 4, 4)");

/// `count` poses of 16 numbers each, row-major, read as poses_from(..., loose = true) does.
std::vector<RigidTransform> loose_poses(const double* data, py::ssize_t count,
                                        const std::string& what);

py::array_t<double> array_of(const Eigen::Matrix4d& M);
py::array_t<double> array_of(const std::vector<RigidTransform>& poses);
/// Always (n, 3), also for n = 0, so that user code can index columns without a special case.
py::array_t<double> array_of(const std::vector<Eigen::Vector3d>& points);
py::array_t<double> array_of(const Eigen::VectorXd& v);

/// What the callable's arguments are: NumPy arrays, or torch tensors on a device.
struct ArrayKind {
  bool torch = false;
  py::object device = py::none();  ///< a torch device or its name ("cuda:0"); None: the CPU
};

/// `array` ("numpy" or "torch") and `device` (None, a name or a torch.device) checked: ValueError
/// for another name, a device without array="torch", or torch that does not import.
ArrayKind array_kind_of(const std::string& array, py::handle device);

/// `a` as the callable wants it: itself, or torch.from_numpy(a) on the device (float64).
py::object for_callable(py::array_t<double> a, const ArrayKind& kind);
/// The same for float32 images (torch.float32 tensors).
py::object for_callable(py::array_t<float> a, const ArrayKind& kind);

/// Stacked arguments of scenes of one shape: (B, H+1, 4, 4), (B, K, 4, 4), (B, n, 3), (B, m, 3),
/// (B, d), a number per scene (B,) (a policy's history and extra poses: pose_layouts.hpp).
py::array_t<double> stacked_history(const std::vector<const Scene*>& scenes);
py::array_t<double> stacked_chunk(const std::vector<const Scene*>& scenes);
py::array_t<double> stacked_hand_points(const std::vector<const Scene*>& scenes);
py::array_t<double> stacked_world_points(const std::vector<const Scene*>& scenes);
py::array_t<double> stacked_vectors(const std::vector<const Eigen::VectorXd*>& vectors);
py::array_t<double> stacked_scalar(const std::vector<const Scene*>& scenes, std::size_t index);

}  // namespace handcentric::python
