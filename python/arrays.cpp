#include "arrays.hpp"

#include <pybind11/stl.h>
#include <cmath>
#include <cstring>

namespace handcentric::python {
namespace {

Eigen::Matrix4d matrix4(const double* m) {
  Eigen::Matrix4d M;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) M(r, c) = m[4 * r + c];
  return M;
}

bool is_torch_tensor(py::handle value) {
  const auto type = py::type::handle_of(value);
  if (!py::hasattr(type, "__module__")) return false;
  const std::string module = py::str(type.attr("__module__"));
  return module.rfind("torch", 0) == 0 && py::hasattr(value, "detach") &&
         py::hasattr(value, "numpy");
}

// One pose's 16 numbers, row-major, at out.
void write_pose(const RigidTransform& T, double* out) {
  const Eigen::Matrix3d& R = T.rotation().matrix();
  const Eigen::Vector3d& p = T.translation();
  for (int r = 0; r < 3; ++r) {
    out[0] = R(r, 0), out[1] = R(r, 1), out[2] = R(r, 2), out[3] = p(r);
    out += 4;
  }
  out[0] = 0.0, out[1] = 0.0, out[2] = 0.0, out[3] = 1.0;
}

using PosesOf = const std::vector<RigidTransform>& (*)(const Scene&);
using PointsOf = const std::vector<Eigen::Vector3d>& (*)(const Scene&);

py::array_t<double> stacked_poses(const std::vector<const Scene*>& scenes, PosesOf poses) {
  const auto B = static_cast<py::ssize_t>(scenes.size());
  const auto n = static_cast<py::ssize_t>(B ? poses(*scenes[0]).size() : 0);
  py::array_t<double> a({B, n, py::ssize_t{4}, py::ssize_t{4}});
  double* out = a.mutable_data();
  for (const Scene* s : scenes) {
    for (const RigidTransform& T : poses(*s)) {
      write_pose(T, out);
      out += 16;
    }
  }
  return a;
}

py::array_t<double> stacked_points(const std::vector<const Scene*>& scenes, PointsOf points) {
  const auto B = static_cast<py::ssize_t>(scenes.size());
  const auto n = static_cast<py::ssize_t>(B ? points(*scenes[0]).size() : 0);
  py::array_t<double> a({B, n, py::ssize_t{3}});
  double* out = a.mutable_data();
  for (const Scene* s : scenes) {
    for (const Eigen::Vector3d& q : points(*s)) {
      out[0] = q(0), out[1] = q(1), out[2] = q(2);
      out += 3;
    }
  }
  return a;
}

}  // namespace

std::string shape_of(const py::array& a) {
  std::ostringstream out;
  out << "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) out << (i ? ", " : "") << a.shape(i);
  out << (a.ndim() == 1 ? ",)" : ")");
  return out.str();
}

std::string type_name(py::handle value) {
  return py::str(py::type::handle_of(value).attr("__name__"));
}

RealArray real_array(py::handle value, const std::string& what) {
  if (value.is_none()) throw DtypeError(what + " is None; expected an array of real numbers");
  py::object readable = py::reinterpret_borrow<py::object>(value);
  if (is_torch_tensor(value)) {
    // NumPy cannot read a tensor that requires grad or lives on a GPU: the audit only reads
    // values, so it takes them as they are, in float64 on the CPU.
    readable = readable.attr("detach")().attr("to")("cpu").attr("double")().attr("numpy")();
  }
  py::array any = py::array::ensure(readable);
  if (!any) {
    throw DtypeError(what + " is a " + type_name(value) +
                     " that NumPy cannot read as an array of real numbers");
  }
  const char kind = any.dtype().kind();
  if (kind != 'f' && kind != 'i' && kind != 'u') {
    throw DtypeError(what + " has dtype " + std::string(py::str(any.dtype())) +
                     "; expected real numbers (float64, float32 or integers)");
  }
  return RealArray::ensure(any);
}

void require_finite(const double* data, py::ssize_t n, const std::string& what) {
  for (py::ssize_t i = 0; i < n; ++i) {
    if (!std::isfinite(data[i])) {
      throw InvalidArgument(what + " holds a non-finite number (" + std::to_string(data[i]) +
                            ") at flat index " + std::to_string(i) +
                            "; every entry must be finite");
    }
  }
}

Eigen::VectorXd vector_from(py::handle value, const std::string& what) {
  const auto a = real_array(value, what);
  if (a.ndim() != 1)
    throw ShapeError(what + " has shape " + shape_of(a) + "; expected a 1-D array (n,)");
  require_finite(a.data(), a.size(), what);
  return Eigen::Map<const Eigen::VectorXd>(a.data(), a.size());
}

Eigen::Vector3d vector3_from(py::handle value, const std::string& what) {
  const Eigen::VectorXd v = vector_from(value, what);
  if (v.size() != 3)
    throw ShapeError(what + " has shape (" + std::to_string(v.size()) + ",); expected (3,)");
  return v;
}

std::vector<RigidTransform> loose_poses(const double* data, py::ssize_t count,
                                        const std::string& what) {
  std::vector<RigidTransform> out;
  out.reserve(static_cast<std::size_t>(count));
  for (py::ssize_t k = 0; k < count; ++k) {
    const Eigen::Matrix4d M = matrix4(data + 16 * k);
    const double row =
        std::abs(M(3, 0)) + std::abs(M(3, 1)) + std::abs(M(3, 2)) + std::abs(M(3, 3) - 1.0);
    if (!(row <= 1e-6)) {
      throw ShapeError(what + "[" + std::to_string(k) + "] has last row (" +
                       std::to_string(M(3, 0)) + ", " + std::to_string(M(3, 1)) + ", " +
                       std::to_string(M(3, 2)) + ", " + std::to_string(M(3, 3)) +
                       "); a pose is [[R, p], [0, 0, 0, 1]]");
    }
    out.push_back(RigidTransform::unchecked(M.topLeftCorner<3, 3>(), M.topRightCorner<3, 1>()));
  }
  return out;
}

std::vector<RigidTransform> poses_from(py::handle value, const std::string& what, bool loose,
                                       const char* expected) {
  const auto a = real_array(value, what);
  if (a.ndim() != 3 || a.shape(1) != 4 || a.shape(2) != 4 || a.shape(0) < 1) {
    throw ShapeError(what + " has shape " + shape_of(a) + "; expected " + expected +
                     " with at least one pose");
  }
  require_finite(a.data(), a.size(), what);
  if (loose) return loose_poses(a.data(), a.shape(0), what);
  std::vector<RigidTransform> out;
  out.reserve(static_cast<std::size_t>(a.shape(0)));
  for (py::ssize_t k = 0; k < a.shape(0); ++k)
    out.push_back(RigidTransform::from_matrix(matrix4(a.data() + 16 * k)));
  return out;
}

Eigen::Matrix4d matrix4_from(py::handle value, const std::string& what) {
  const auto a = real_array(value, what);
  if (a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4) {
    throw ShapeError(what + " has shape " + shape_of(a) + "; expected (4, 4)");
  }
  require_finite(a.data(), a.size(), what);
  return matrix4(a.data());
}

std::vector<Eigen::Vector3d> points_from(py::handle value, const std::string& what) {
  if (value.is_none()) return {};
  const auto a = real_array(value, what);
  if (a.size() == 0) return {};
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw ShapeError(what + " has shape " + shape_of(a) + "; expected (n, 3)");
  require_finite(a.data(), a.size(), what);
  std::vector<Eigen::Vector3d> out(static_cast<std::size_t>(a.shape(0)));
  for (py::ssize_t i = 0; i < a.shape(0); ++i)
    out[static_cast<std::size_t>(i)] = Eigen::Vector3d(a.data() + 3 * i);
  return out;
}

py::array_t<double> array_of(const Eigen::Matrix4d& M) {
  py::array_t<double> a({4, 4});
  double* out = a.mutable_data();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out[4 * r + c] = M(r, c);
  return a;
}

py::array_t<double> array_of(const std::vector<RigidTransform>& poses) {
  py::array_t<double> a({static_cast<py::ssize_t>(poses.size()), py::ssize_t{4}, py::ssize_t{4}});
  double* out = a.mutable_data();
  for (const RigidTransform& T : poses) {
    write_pose(T, out);
    out += 16;
  }
  return a;
}

py::array_t<double> array_of(const std::vector<Eigen::Vector3d>& points) {
  py::array_t<double> a({static_cast<py::ssize_t>(points.size()), py::ssize_t{3}});
  double* out = a.mutable_data();
  for (const Eigen::Vector3d& q : points) {
    out[0] = q(0), out[1] = q(1), out[2] = q(2);
    out += 3;
  }
  return a;
}

py::array_t<double> array_of(const Eigen::VectorXd& v) {
  py::array_t<double> a(v.size());
  std::memcpy(a.mutable_data(), v.data(), sizeof(double) * static_cast<std::size_t>(v.size()));
  return a;
}

py::array_t<double> stacked_history(const std::vector<const Scene*>& scenes) {
  return stacked_poses(scenes, [](const Scene& s) -> const std::vector<RigidTransform>& {
    return s.world_T_hand_history;
  });
}

py::array_t<double> stacked_chunk(const std::vector<const Scene*>& scenes) {
  return stacked_poses(scenes, [](const Scene& s) -> const std::vector<RigidTransform>& {
    return s.world_T_hand_chunk;
  });
}

py::array_t<double> stacked_hand_points(const std::vector<const Scene*>& scenes) {
  return stacked_points(
      scenes, [](const Scene& s) -> const std::vector<Eigen::Vector3d>& { return s.hand_points; });
}

py::array_t<double> stacked_world_points(const std::vector<const Scene*>& scenes) {
  return stacked_points(
      scenes, [](const Scene& s) -> const std::vector<Eigen::Vector3d>& { return s.world_points; });
}

py::array_t<double> stacked_vectors(const std::vector<const Eigen::VectorXd*>& vectors) {
  const auto B = static_cast<py::ssize_t>(vectors.size());
  const auto d = static_cast<py::ssize_t>(B ? vectors[0]->size() : 0);
  py::array_t<double> a({B, d});
  double* out = a.mutable_data();
  for (const Eigen::VectorXd* v : vectors) {
    std::memcpy(out, v->data(), sizeof(double) * static_cast<std::size_t>(d));
    out += d;
  }
  return a;
}

py::array_t<double> stacked_scalar(const std::vector<const Scene*>& scenes, std::size_t index) {
  py::array_t<double> a(static_cast<py::ssize_t>(scenes.size()));
  double* out = a.mutable_data();
  for (const Scene* s : scenes) *out++ = s->scalars.at(index).second;
  return a;
}

ArrayKind array_kind_of(const std::string& array, py::handle device) {
  ArrayKind kind;
  if (array == "numpy") {
    if (!device.is_none()) {
      throw InvalidArgument("device=" + std::string(py::str(device)) +
                            " needs array=\"torch\"; NumPy arrays live on the CPU");
    }
    return kind;
  }
  if (array != "torch")
    throw InvalidArgument("array=\"" + array + "\" is not known; use \"numpy\" or \"torch\"");
  try {
    (void)py::module_::import("torch");
  } catch (py::error_already_set& e) {
    throw InvalidArgument("array=\"torch\" needs torch, which does not import here (" +
                          std::string(py::str(e.value())) + ")");
  }
  kind.torch = true;
  kind.device = py::reinterpret_borrow<py::object>(device);
  return kind;
}

namespace {

py::object as_tensor(py::array a, const ArrayKind& kind) {
  static py::object from_numpy = py::module_::import("torch").attr("from_numpy");
  py::object tensor = from_numpy(std::move(a));
  if (!kind.device.is_none()) tensor = tensor.attr("to")(kind.device);
  return tensor;
}

}  // namespace

py::object for_callable(py::array_t<double> a, const ArrayKind& kind) {
  if (!kind.torch) return a;
  return as_tensor(std::move(a), kind);
}

py::object for_callable(py::array_t<float> a, const ArrayKind& kind) {
  if (!kind.torch) return a;
  return as_tensor(std::move(a), kind);
}

}  // namespace handcentric::python
