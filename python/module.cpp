// `import handcentric`: the audit of docs/AUDIT.md, in process, on Python callables and NumPy
// arrays (docs/AUDIT_YOUR_POLICY.md). The callables are wrapped in the library's own
// Representation and NoisyPolicy interfaces, so the checks, tolerances, witnesses and JSON are
// exactly those of `handcentric audit`; only the transport differs from --exec (a function call
// instead of a pipe).
//
// Errors. The checks stop and rethrow a handcentric::Error thrown by the function under test and
// treat any other exception as a counterexample (props/src/check.cpp). A Python exception inside
// a callable is therefore carried through the checks as PythonCallError (a handcentric::Error
// holding the Python exception) and restored, traceback included, once the C++ call returns.
// A result of the wrong shape or dtype stops the audit with ShapeError / DtypeError naming what
// was returned and what was expected. The GIL is held throughout: the checks are sequential.
//
// No verdict without evidence. The audits need NumPy to build the callables' arguments: without
// it they raise ImportError at once, naming the interpreter and the fix, instead of checking
// anything. Ctrl-C: a signal reaches Python only when PyErr_CheckSignals() runs, so every call
// of a callable checks first, and a pending KeyboardInterrupt stops the check as the callable's
// own exception would. cases and noise are read as Python integers and refused above
// props::kMaxCases and props::kMaxPolicyNoise (the CLI's bounds) with a one-line ValueError.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/representations.hpp"
#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/scene.hpp"
#include "handcentric/core/so3.hpp"
#include "handcentric/props/audit.hpp"
#include "handcentric/props/check.hpp"
#include "handcentric/props/classifier.hpp"
#include "handcentric/props/plugin_protocol.hpp"
#include "handcentric/props/policy_audit.hpp"
#include "handcentric/props/verdict.hpp"
#include "handcentric/sim/demos.hpp"

namespace py = pybind11;

namespace handcentric::python {
namespace {

// ---------------------------------------------------------------------------------------------
// Errors

/// A Python exception raised inside a callable under audit, carried through the C++ checks.
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

/// `value` as a C-contiguous float64 array; DtypeError for anything that is not real numbers
/// (lists, tuples, NumPy arrays of any integer or float dtype and objects with __array__, such
/// as CPU torch tensors without grad, are fine).
using RealArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

RealArray real_array(py::handle value, const std::string& what) {
  if (value.is_none()) throw DtypeError(what + " is None; expected an array of real numbers");
  py::array any = py::array::ensure(value);
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

Eigen::Matrix4d matrix4(const double* m) {
  Eigen::Matrix4d M;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) M(r, c) = m[4 * r + c];
  return M;
}

/// A stack of poses (n, 4, 4), n >= 1; each validated as a rigid transform unless `loose`, where
/// the rotation block is taken as it is (a float32 policy's is orthonormal to ~1e-7 only, as for
/// the --policy-exec pipe) and only the last row is checked (to 1e-6).
std::vector<RigidTransform> poses_from(py::handle value, const std::string& what,
                                       bool loose = false, const char* expected = "(n, 4, 4)") {
  const auto a = real_array(value, what);
  if (a.ndim() != 3 || a.shape(1) != 4 || a.shape(2) != 4 || a.shape(0) < 1) {
    throw ShapeError(what + " has shape " + shape_of(a) + "; expected " + expected +
                     " with at least one pose");
  }
  require_finite(a.data(), a.size(), what);
  std::vector<RigidTransform> out;
  out.reserve(static_cast<std::size_t>(a.shape(0)));
  for (py::ssize_t k = 0; k < a.shape(0); ++k) {
    const Eigen::Matrix4d M = matrix4(a.data() + 16 * k);
    if (!loose) {
      out.push_back(RigidTransform::from_matrix(M));
      continue;
    }
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

// ---------------------------------------------------------------------------------------------
// C++ -> NumPy

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
    const Eigen::Matrix3d& R = T.rotation().matrix();
    const Eigen::Vector3d& p = T.translation();
    for (int r = 0; r < 3; ++r) {
      out[0] = R(r, 0), out[1] = R(r, 1), out[2] = R(r, 2), out[3] = p(r);
      out += 4;
    }
    out[0] = 0.0, out[1] = 0.0, out[2] = 0.0, out[3] = 1.0;
    out += 4;
  }
  return a;
}

/// Always (n, 3), also for n = 0, so that user code can index columns without a special case.
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

// ---------------------------------------------------------------------------------------------
// Callables under audit

/// The name a report shows for a callable: a function's qualified name, else its class's (an
/// object with __call__, e.g. a torch module), so that the name does not change between runs.
std::string callable_name(const py::object& fn) {
  if (py::hasattr(fn, "__qualname__")) return py::str(fn.attr("__qualname__"));
  return py::str(py::type::handle_of(fn).attr("__qualname__"));
}

/// The keyword arguments extra_poses={name: (4, 4)} and scalars={name: float}, when the audit
/// was asked for any (as handcentric_plugin.serve gives them).
py::kwargs extras_kwargs(const Scene& scene, bool wanted) {
  py::kwargs kw;
  if (!wanted) return kw;
  py::dict poses, scalars;
  for (const auto& [name, pose] : scene.extra_poses) poses[py::str(name)] = array_of(pose.matrix());
  for (const auto& [name, x] : scene.scalars) scalars[py::str(name)] = x;
  kw["extra_poses"] = poses;
  kw["scalars"] = scalars;
  return kw;
}

/// Calls fn; a Python exception leaves as PythonCallError (see the top of this file), and so
/// does a KeyboardInterrupt (or any exception a signal handler raises) pending before the call:
/// a callable written in C runs no Python code that would notice it.
template <class... Args>
py::object call(const py::object& fn, Args&&... args) {
  try {
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    return fn(std::forward<Args>(args)...);
  } catch (py::error_already_set& e) {
    throw PythonCallError(std::move(e));
  }
}

/// The bytes of a scene's observation (and chunk, when asked): a cache key.
void append(std::string& key, const RigidTransform& T) {
  key.append(reinterpret_cast<const char*>(T.rotation().matrix().data()), 9 * sizeof(double));
  key.append(reinterpret_cast<const char*>(T.translation().data()), 3 * sizeof(double));
}

std::string scene_key(const Scene& scene, bool with_chunk) {
  std::string key;
  key.reserve(96 * (scene.world_T_hand_history.size() + scene.world_T_hand_chunk.size()) + 64);
  auto count = [&key](std::size_t n) { key.append(reinterpret_cast<const char*>(&n), sizeof(n)); };
  count(scene.world_T_hand_history.size());
  for (const RigidTransform& T : scene.world_T_hand_history) append(key, T);
  count(with_chunk ? scene.world_T_hand_chunk.size() : 0);
  if (with_chunk)
    for (const RigidTransform& T : scene.world_T_hand_chunk) append(key, T);
  for (const auto* points : {&scene.hand_points, &scene.world_points}) {
    count(points->size());
    for (const Eigen::Vector3d& q : *points)
      key.append(reinterpret_cast<const char*>(q.data()), 3 * sizeof(double));
  }
  for (const auto& [name, T] : scene.extra_poses) append(key, T);
  for (const auto& [name, x] : scene.scalars)
    key.append(reinterpret_cast<const char*>(&x), sizeof(x));
  return key;
}

/// A bounded cache: the checks ask the same scene many times (every component of a cell, and
/// an exact in-distribution check n + 3 times), a Python call costs microseconds.
template <class Value>
class Cache {
 public:
  const Value* find(const std::string& key) const {
    const auto hit = map_.find(key);
    return hit == map_.end() ? nullptr : &hit->second;
  }
  const Value& put(std::string key, Value value) {
    // By count and by key bytes: a policy's key holds its noise vector (up to 512 KiB).
    if (map_.size() > 200000 || key_bytes_ > (std::size_t{256} << 20)) {
      map_.clear();
      key_bytes_ = 0;
    }
    key_bytes_ += key.size();
    return map_.insert_or_assign(std::move(key), std::move(value)).first->second;
  }

 private:
  std::unordered_map<std::string, Value> map_;
  std::size_t key_bytes_ = 0;
};

/// A representation written in Python: actions(history, chunk, hand_points, world_points) and,
/// optionally, observation(history, hand_points, world_points) and decode(actions, history,
/// hand_points, world_points) -> (K, 4, 4).
class PythonRepresentation final : public Representation {
 public:
  PythonRepresentation(py::object actions, py::object observation, py::object decode, bool extras)
      : actions_(std::move(actions)),
        observation_(std::move(observation)),
        decode_(std::move(decode)),
        extras_(extras),
        name_("python: " + callable_name(actions_)) {}

  std::string name() const override { return name_; }
  bool has_observation() const { return !observation_.is_none(); }

  Eigen::VectorXd encode_actions(const Scene& scene) const override {
    scene.validate();
    std::string key = scene_key(scene, true);
    if (const auto* hit = actions_cache_.find(key)) return *hit;
    py::object result = call(actions_, array_of(scene.world_T_hand_history),
                             array_of(scene.world_T_hand_chunk), array_of(scene.hand_points),
                             array_of(scene.world_points), **extras_kwargs(scene, extras_));
    return actions_cache_.put(std::move(key),
                              vector_from(result, "the result of actions function " + name_));
  }

  Eigen::VectorXd encode_observation(const Scene& scene) const override {
    if (!has_observation()) return {};
    scene.validate_observation();
    std::string key = scene_key(scene, false);
    if (const auto* hit = observation_cache_.find(key)) return *hit;
    py::object result =
        call(observation_, array_of(scene.world_T_hand_history), array_of(scene.hand_points),
             array_of(scene.world_points), **extras_kwargs(scene, extras_));
    return observation_cache_.put(
        std::move(key),
        vector_from(result, "the result of observation function " + callable_name(observation_)));
  }

  bool can_decode() const override { return !decode_.is_none(); }

  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd& actions,
                                             const RigidTransform& world_T_hand0) const override {
    Scene observation;
    observation.world_T_hand_history = {world_T_hand0};
    return decode_in_scene(actions, observation);
  }

  std::vector<RigidTransform> decode_in_scene(const Eigen::VectorXd& actions,
                                              const Scene& observation) const override {
    if (!can_decode())
      throw InvalidArgument(name_ + " has no decode function: pass decode= to audit it");
    py::object result = call(decode_, array_of(actions), array_of(observation.world_T_hand_history),
                             array_of(observation.hand_points), array_of(observation.world_points),
                             **extras_kwargs(observation, extras_));
    return poses_from(result, "the result of decode function " + callable_name(decode_), true,
                      "(K, 4, 4)");
  }

 private:
  py::object actions_, observation_, decode_;
  bool extras_;
  std::string name_;
  mutable Cache<Eigen::VectorXd> actions_cache_, observation_cache_;
};

/// A whole policy written in Python: policy(history, hand_points, world_points, noise) -> the
/// world-frame chunk T_1..T_K, (K, 4, 4). The noise is its only randomness.
class PythonPolicy final : public props::NoisyPolicy {
 public:
  PythonPolicy(py::object policy, Eigen::Index noise, bool extras)
      : policy_(std::move(policy)),
        noise_(noise),
        extras_(extras),
        name_("python: " + callable_name(policy_)) {}

  std::string name() const override { return name_; }
  Eigen::Index noise_dimension() const override { return noise_; }

  std::vector<RigidTransform> act(const Scene& observation,
                                  const Eigen::VectorXd& noise) const override {
    observation.validate_observation();
    std::string key = scene_key(observation, false);
    key.append(reinterpret_cast<const char*>(noise.data()),
               sizeof(double) * static_cast<std::size_t>(noise.size()));
    if (const auto* hit = cache_.find(key)) return *hit;
    py::object result = call(policy_, array_of(observation.world_T_hand_history),
                             array_of(observation.hand_points), array_of(observation.world_points),
                             array_of(noise), **extras_kwargs(observation, extras_));
    std::vector<RigidTransform> chunk =
        poses_from(result, "the chunk returned by policy " + name_, true, "(K, 4, 4)");
    if (chunk_length_ == 0) chunk_length_ = chunk.size();
    if (chunk.size() != chunk_length_) {
      throw ShapeError("policy " + name_ + " returned " + std::to_string(chunk.size()) +
                       " poses after " + std::to_string(chunk_length_) +
                       " earlier; the chunk length K must not change");
    }
    return cache_.put(std::move(key), std::move(chunk));
  }

 private:
  py::object policy_;
  Eigen::Index noise_;
  bool extras_;
  std::string name_;
  mutable std::size_t chunk_length_ = 0;
  mutable Cache<std::vector<RigidTransform>> cache_;
};

// ---------------------------------------------------------------------------------------------
// Options

/// A name or a sequence of names.
std::vector<std::string> names_of(py::handle value, const std::string& what) {
  if (py::isinstance<py::str>(value)) return {value.cast<std::string>()};
  try {
    return value.cast<std::vector<std::string>>();
  } catch (const py::cast_error&) {
    throw DtypeError(what + " must be a name or a sequence of names, got a " + type_name(value));
  }
}

std::vector<props::Group> groups_of(py::handle value) {
  std::vector<props::Group> out;
  for (const std::string& name : names_of(value, "groups")) {
    if (name == "all") return props::all_groups();
    out.push_back(props::parse_group(name));  // InvalidArgument naming the valid names
  }
  if (out.empty())
    throw InvalidArgument(
        "groups is empty; name at least one of translation, rotation, se2, se3, c8");
  return out;
}

std::vector<props::View> views_of(py::handle value) {
  std::vector<props::View> out;
  for (const std::string& name : names_of(value, "views")) {
    if (name == "all") return {props::View::eye_in_hand, props::View::third_person};
    if (name == "eye_in_hand") {
      out.push_back(props::View::eye_in_hand);
    } else if (name == "third_person") {
      out.push_back(props::View::third_person);
    } else {
      throw InvalidArgument("unknown view '" + name + "'; use eye_in_hand, third_person or all");
    }
  }
  if (out.empty()) throw InvalidArgument("views is empty; name eye_in_hand, third_person or both");
  return out;
}

/// ImportError, at once, unless NumPy imports: every argument of a callable under audit is a
/// NumPy array, and without NumPy no case could run (an audit used to report every cell failed
/// on 0 cases then).
void require_numpy(const char* function) {
  static bool found = false;
  if (found) return;
  try {
    (void)py::module_::import("numpy");
    found = true;
  } catch (py::error_already_set& e) {
    const std::string why = py::str(e.value());
    const std::string executable = py::str(py::module_::import("sys").attr("executable"));
    const std::string message =
        "handcentric." + std::string(function) + " needs NumPy, which the interpreter " +
        executable + " cannot import (" + why +
        "); nothing was checked. Debian: apt-get install python3-numpy and run /usr/bin/python3 "
        "(without -S); in a venv: pip install numpy";
    py::raise_from(e, PyExc_ImportError, message.c_str());
    throw py::error_already_set();
  }
}

/// `value` (a Python int of any size, or anything with __index__ such as a NumPy integer) in
/// [low, high]: TypeError for a non-integer, a one-line ValueError naming the value and the
/// bound otherwise, before anything is converted to a C++ int or allocated.
int bounded_integer(py::handle value, const char* name, long long low, long long high,
                    const char* bound) {
  if (!PyIndex_Check(value.ptr()))
    throw DtypeError(std::string(name) + " must be an integer, got a " + type_name(value));
  const auto index = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
  if (!index) throw py::error_already_set();
  int overflow = 0;
  const long long x = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
  if (overflow == 0 && x >= low && x <= high) return static_cast<int>(x);
  const std::string text = std::string(name) + "=" + std::string(py::str(index));
  if (overflow < 0 || (overflow == 0 && x < low))
    throw InvalidArgument(text + " is below the least value, " + std::to_string(low));
  throw InvalidArgument(text + " is above the bound " + bound + " = " + std::to_string(high) +
                        " (docs/AUDIT_YOUR_POLICY.md says why)");
}

int cases_of(py::handle cases) {
  return bounded_integer(cases, "cases", 1, props::kMaxCases, "handcentric.MAX_CASES");
}

int noise_of(py::handle noise) {
  return bounded_integer(noise, "noise", 1, props::kMaxPolicyNoise, "handcentric.MAX_NOISE");
}

struct CommonOptions {
  props::AuditOptions audit;
  std::vector<std::string> extra_poses, scalars;
};

CommonOptions common_options(py::handle groups, py::handle views, py::handle cases,
                             std::uint64_t seed, std::optional<double> tolerance,
                             const std::string& precision, py::handle extra_poses,
                             py::handle scalars) {
  CommonOptions o;
  o.audit.cases = cases_of(cases);
  o.audit.groups = groups_of(groups);
  o.audit.views = views_of(views);
  o.audit.seed = seed;
  o.audit.precision = props::parse_precision(precision);
  if (tolerance) {
    if (!(*tolerance > 0.0)) {
      throw InvalidArgument("tolerance must be in (0, 1), got " + std::to_string(*tolerance) +
                            "; or leave it None for the precision's (1e-9 float64, 1e-4 float32)");
    }
    o.audit.relative_tolerance = *tolerance;
  }
  (void)props::audit_relative_tolerance(o.audit);  // validates the tolerance
  o.extra_poses = names_of(extra_poses, "extra_poses");
  o.scalars = names_of(scalars, "scalars");
  return o;
}

props::ClassifierOptions classifier_for(const CommonOptions& o) {
  props::ClassifierOptions c = props::classifier_options(o.audit);
  c.float32_advice = "pass precision=\"float32\"";
  c.check.shape.extra_pose_names = o.extra_poses;
  c.check.shape.scalar_names = o.scalars;
  return c;
}

py::object json_loads(const std::string& text) {
  return py::module_::import("json").attr("loads")(text);
}

// ---------------------------------------------------------------------------------------------
// Assertions

std::string describe(const props::Verdict& v, const std::string& name, bool policy) {
  std::ostringstream out;
  out << name << ": " << (policy ? "not equivariant" : to_string(v.component) + " not invariant")
      << " under " << props::to_string(v.group) << " (" << props::to_string(v.mode) << ", "
      << props::to_string(v.view) << ", " << props::to_string(v.method) << "); largest error "
      << v.max_error << ", failed at case " << v.cases + v.near_identity_cases << ", seed "
      << v.seed << ", tolerance " << v.relative_tolerance << " (1 + L)\n";
  if (!v.note.empty()) out << "  note: " << v.note << "\n";
  if (v.witness) {
    out << "  shrunk witness (poses as rotation vector r and translation p; before/after = "
        << (policy ? "g a(o) and a(g o), each pose [p, r(R)]" : "f(s) and f(g s)") << "):\n";
    std::istringstream lines(props::format_witness(*v.witness));
    for (std::string line; std::getline(lines, line);) out << "    " << line << "\n";
  }
  return out.str();
}

[[noreturn]] void raise_assertion(const std::string& message) {
  PyErr_SetString(PyExc_AssertionError, message.c_str());
  throw py::error_already_set();
}

void assert_all_hold(const props::Classification& c, bool policy, const std::string& hint) {
  std::string failures;
  int failed = 0;
  for (const props::Verdict& v : c.verdicts) {
    if (v.invariant) continue;
    ++failed;
    failures += describe(v, c.name, policy);
  }
  if (failed == 0) return;
  raise_assertion(std::to_string(failed) + " of " + std::to_string(c.verdicts.size()) +
                  " checks failed\n" + failures + hint);
}

props::Component component_of(const std::string& name) {
  for (props::Component c : {props::Component::actions, props::Component::observation,
                             props::Component::flow_input, props::Component::flow_target}) {
    if (props::to_string(c) == name) return c;
  }
  throw InvalidArgument("unknown component '" + name +
                        "'; use actions, observation, flow_input or flow_target");
}

// ---------------------------------------------------------------------------------------------
// The module's functions

py::dict audit(py::object actions, py::object observation, py::handle groups, py::handle views,
               py::handle cases, std::uint64_t seed, std::optional<double> tolerance,
               const std::string& precision, py::object decode, py::handle extra_poses,
               py::handle scalars) {
  require_numpy("audit");
  if (!PyCallable_Check(actions.ptr()))
    throw DtypeError("actions must be callable, got a " + type_name(actions));
  for (const auto& [what, fn] :
       {std::pair<const char*, py::handle>{"observation", observation}, {"decode", decode}}) {
    if (!fn.is_none() && !PyCallable_Check(fn.ptr())) {
      throw DtypeError(std::string(what) + " must be callable or None, got a " + type_name(fn));
    }
  }
  const CommonOptions o =
      common_options(groups, views, cases, seed, tolerance, precision, extra_poses, scalars);
  const bool extras = !o.extra_poses.empty() || !o.scalars.empty();
  auto representation =
      std::make_shared<PythonRepresentation>(actions, observation, decode, extras);
  props::ClassifierOptions c = classifier_for(o);
  c.observation = representation->has_observation();
  const props::Classification result = props::classify_representation(representation, c);
  return json_loads(props::audit_json({result}))["representations"][py::int_(0)];
}

py::dict audit_policy(py::object policy, py::handle groups, py::handle views, py::handle cases,
                      std::uint64_t seed, std::optional<double> tolerance,
                      const std::string& precision, py::handle noise_length, py::handle extra_poses,
                      py::handle scalars) {
  require_numpy("audit_policy");
  if (!PyCallable_Check(policy.ptr()))
    throw DtypeError("policy must be callable, got a " + type_name(policy));
  const int noise = noise_of(noise_length);
  const CommonOptions o =
      common_options(groups, views, cases, seed, tolerance, precision, extra_poses, scalars);
  const bool extras = !o.extra_poses.empty() || !o.scalars.empty();
  const props::Classification result = props::classify_policy(
      std::make_shared<PythonPolicy>(policy, noise, extras), classifier_for(o));
  return json_loads(props::policy_audit_json({result}))["policies"][py::int_(0)];
}

void assert_invariant(py::object fn, const std::string& group, const std::string& component_name,
                      py::object observation, py::handle views, py::handle cases,
                      std::uint64_t seed, std::optional<double> tolerance,
                      const std::string& precision, py::handle extra_poses, py::handle scalars) {
  require_numpy("assert_invariant");
  if (!PyCallable_Check(fn.ptr())) throw DtypeError("fn must be callable, got a " + type_name(fn));
  const props::Component component = component_of(component_name);
  const CommonOptions o = common_options(py::str(group), views, cases, seed, tolerance, precision,
                                         extra_poses, scalars);
  const bool extras = !o.extra_poses.empty() || !o.scalars.empty();
  props::ClassifierOptions c = classifier_for(o);
  props::Classification result;
  if (component == props::Component::observation) {
    // fn is the observation function; the actions are never asked for.
    auto representation = std::make_shared<PythonRepresentation>(
        py::cpp_function([](py::args) { return py::none(); }), fn, py::none(), extras);
    result.name = "python: " + callable_name(fn);
    for (props::View view : c.views) {
      const props::CheckOptions check = props::with_view(c.check, view);
      const props::SceneFunction f = props::observation_of(representation);
      result.verdicts.push_back(props::with_float32_note(
          props::check_invariance(f, component, o.audit.groups[0], check), c,
          [&](const props::CheckOptions& again) {
            return props::check_invariance(f, component, o.audit.groups[0], again);
          }));
    }
  } else {
    auto representation =
        std::make_shared<PythonRepresentation>(fn, observation, py::none(), extras);
    c.observation = false;
    c.injectivity = false;
    c.flow = component != props::Component::actions;
    result = props::classify_representation(representation, c);
    std::erase_if(result.verdicts,
                  [component](const props::Verdict& v) { return v.component != component; });
  }
  assert_all_hold(
      result, false,
      "replay: the same call with seed=" + std::to_string(seed) + " finds the same witness");
}

void assert_equivariant(py::object policy, const std::string& group, const std::string& mode,
                        py::handle views, py::handle cases, std::uint64_t seed,
                        std::optional<double> tolerance, const std::string& precision,
                        py::handle noise_length, py::handle extra_poses, py::handle scalars) {
  require_numpy("assert_equivariant");
  if (!PyCallable_Check(policy.ptr()))
    throw DtypeError("policy must be callable, got a " + type_name(policy));
  const int noise = noise_of(noise_length);
  if (mode != "pointwise" && mode != "distribution" && mode != "both") {
    throw InvalidArgument("unknown mode '" + mode +
                          "'; use pointwise (the same noise for o and g o), "
                          "distribution (independent noise) or both");
  }
  const CommonOptions o = common_options(py::str(group), views, cases, seed, tolerance, precision,
                                         extra_poses, scalars);
  const bool extras = !o.extra_poses.empty() || !o.scalars.empty();
  props::ClassifierOptions c = classifier_for(o);
  c.in_distribution = mode != "pointwise";
  const auto python_policy = std::make_shared<PythonPolicy>(policy, noise, extras);
  props::Classification result = props::classify_policy(python_policy, c);
  if (mode == "distribution") {
    std::erase_if(result.verdicts,
                  [](const props::Verdict& v) { return v.mode != props::Mode::distribution; });
  }
  std::string hint =
      "replay: the same call with seed=" + std::to_string(seed) + " finds the same witness";
  // The hint that the policy may hold in law only where it does: each (group, view) that failed
  // pointwise is checked in distribution (mode 'both' already did), and named if it holds there.
  std::string in_law;
  for (const props::Verdict& v : result.verdicts) {
    if (v.invariant || v.mode != props::Mode::pointwise) continue;
    bool holds = false;
    if (const props::Verdict* law = props::find_verdict(
            result, props::Component::policy, props::Mode::distribution, v.group, v.view)) {
      holds = law->invariant;
    } else {
      props::CheckOptions check = props::with_view(c.check, v.view);
      check.shrink = false;  // only the yes or no is wanted
      holds = props::check_policy_distribution(*python_policy, v.group, check, c.distribution)
                  .invariant;
    }
    if (holds) {
      in_law += (in_law.empty() ? "" : ", ") + props::to_string(v.group) + " (" +
                props::to_string(v.view) + ")";
    }
  }
  if (!in_law.empty()) {
    hint += "\nIn distribution (independent noise for o and g o) it holds for " + in_law +
            ": equivariant in law but not pointwise (e.g. noise added in the world frame); "
            "mode='distribution' asserts the law only.";
  }
  assert_all_hold(result, true, hint);
}

// Built-ins on NumPy

Scene scene_from(py::handle history, py::handle chunk, py::handle hand_points,
                 py::handle world_points) {
  Scene scene;
  scene.world_T_hand_history = poses_from(history, "history", false, "(H+1, 4, 4)");
  if (!chunk.is_none()) scene.world_T_hand_chunk = poses_from(chunk, "chunk", false, "(K, 4, 4)");
  scene.hand_points = points_from(hand_points, "hand_points");
  scene.world_points = points_from(world_points, "world_points");
  return scene;
}

py::dict demo_dict(const sim::Demo& demo) {
  py::dict d;
  d["world_T_hole"] = array_of(demo.world_T_hole.matrix());
  d["world_T_hand"] = array_of(demo.world_T_hand);
  return d;
}

}  // namespace
}  // namespace handcentric::python

PYBIND11_MODULE(_core, m) {
  using namespace handcentric;
  using namespace handcentric::python;
  namespace props = handcentric::props;
  m.doc() =
      "Audit action representations and whole policies for equivariance under global rigid "
      "transforms (docs/AUDIT.md, docs/AUDIT_YOUR_POLICY.md).";
  m.attr("__version__") = HANDCENTRIC_VERSION;

  static py::exception<Error> error_type(m, "Error", PyExc_RuntimeError);
  static py::exception<ShapeError> shape_error_type(m, "ShapeError", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const PythonCallError& e) {
      e.error->restore();  // the callable's own exception, with its traceback
    } catch (const ShapeError& e) {
      PyErr_SetString(shape_error_type.ptr(), e.what());
    } catch (const DtypeError& e) {
      PyErr_SetString(PyExc_TypeError, e.what());
    } catch (const InvalidArgument& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const Error& e) {
      PyErr_SetString(error_type.ptr(), e.what());
    }
  });

  const auto all_groups = py::make_tuple("translation", "rotation", "se2", "se3", "c8");
  const auto both_views = py::make_tuple("eye_in_hand", "third_person");
  m.attr("GROUPS") = all_groups;
  m.attr("VIEWS") = both_views;
  m.attr("REPRESENTATIONS") = py::cast(builtin_representation_names());
  m.attr("MAX_CASES") = props::kMaxCases;        // cases= above it: ValueError
  m.attr("MAX_NOISE") = props::kMaxPolicyNoise;  // noise= above it: ValueError

  m.def("audit", &audit, py::arg("actions"), py::arg("observation") = py::none(),
        py::arg("groups") = all_groups, py::arg("views") = both_views,
        py::arg("cases") = props::kDefaultCases, py::arg("seed") = 1,
        py::arg("tolerance") = py::none(), py::arg("precision") = "float64", py::kw_only(),
        py::arg("decode") = py::none(), py::arg("extra_poses") = py::tuple(),
        py::arg("scalars") = py::tuple(),
        R"doc(Audit a representation written in Python.

Returns one representation of `handcentric audit --json`.
actions(history, chunk, hand_points, world_points) -> 1-D array, with history (H+1, 4, 4)
(index 0 = T_0, the hand now, then T_-1, ...), chunk (K, 4, 4) = T_1..T_K, hand_points (n, 3)
in the hand frame at T_0, world_points (m, 3) in the world frame; every pose is world_T_hand.
observation(history, hand_points, world_points) -> 1-D array (optional).
decode(actions, history, hand_points, world_points) -> (K, 4, 4) (optional: lets the audit
prove the map injective). The flow components are the rectified flow's (eq. 5).
With extra_poses / scalars (names), every callable also gets extra_poses={name: (4, 4)},
scalars={name: x}. cases: 1 to MAX_CASES (10**7). Needs NumPy (ImportError at once without it);
Ctrl-C stops it with KeyboardInterrupt.)doc");

  m.def("audit_policy", &audit_policy, py::arg("policy"), py::arg("groups") = all_groups,
        py::arg("views") = both_views, py::arg("cases") = props::kDefaultCases, py::arg("seed") = 1,
        py::arg("tolerance") = py::none(), py::arg("precision") = "float64",
        py::arg("noise") = props::kPolicyNoise, py::kw_only(), py::arg("extra_poses") = py::tuple(),
        py::arg("scalars") = py::tuple(),
        R"doc(Audit a whole policy (eq. 4) pointwise and in distribution.

Returns one policy of `audit --json`.
policy(history, hand_points, world_points, noise) -> (K, 4, 4), the world-frame chunk
T_1..T_K; noise is a float64 vector of `noise` standard normals and must be the policy's only
randomness. cases: 1 to MAX_CASES (10**7); noise: 1 to MAX_NOISE (65536).)doc");

  m.def("assert_invariant", &assert_invariant, py::arg("fn"), py::arg("group"),
        py::arg("component") = "actions", py::kw_only(), py::arg("observation") = py::none(),
        py::arg("views") = both_views, py::arg("cases") = props::kDefaultCases, py::arg("seed") = 1,
        py::arg("tolerance") = py::none(), py::arg("precision") = "float64",
        py::arg("extra_poses") = py::tuple(), py::arg("scalars") = py::tuple(),
        R"doc(Raise AssertionError unless `component` is invariant under `group`.

The error carries the shrunk witness.
component "actions": fn is the actions function; "observation": fn is the observation
function; "flow_input" / "flow_target": fn is the actions function, observation= the
observation function, and the rectified flow is checked pointwise and in distribution.
Every view in `views` must hold.)doc");

  m.def("assert_equivariant", &assert_equivariant, py::arg("policy"), py::arg("group"),
        py::kw_only(), py::arg("mode") = "pointwise", py::arg("views") = both_views,
        py::arg("cases") = props::kDefaultCases, py::arg("seed") = 1,
        py::arg("tolerance") = py::none(), py::arg("precision") = "float64",
        py::arg("noise") = props::kPolicyNoise, py::arg("extra_poses") = py::tuple(),
        py::arg("scalars") = py::tuple(),
        R"doc(Raise AssertionError unless policy(g o, n) = g policy(o, n) under `group`.

The error carries the shrunk witness.
mode "pointwise" (default: the same noise n for o and g o; Theorem 1's guarantee, which
implies the law's), "distribution" (independent noise: the laws compared) or "both".
Every view in `views` must hold.)doc");

  m.def(
      "encode_actions",
      [](const std::string& name, py::handle history, py::handle chunk, py::handle hand_points,
         py::handle world_points) {
        return array_of(make_representation(name)->encode_actions(
            scene_from(history, chunk, hand_points, world_points)));
      },
      py::arg("representation"), py::arg("history"), py::arg("chunk"),
      py::arg("hand_points") = py::none(), py::arg("world_points") = py::none(),
      "A built-in representation's action vector (6 numbers per pose).");
  m.def(
      "encode_observation",
      [](const std::string& name, py::handle history, py::handle hand_points,
         py::handle world_points) {
        return array_of(make_representation(name)->encode_observation(
            scene_from(history, py::none(), hand_points, world_points)));
      },
      py::arg("representation"), py::arg("history"), py::arg("hand_points") = py::none(),
      py::arg("world_points") = py::none(), "A built-in representation's observation vector.");
  m.def(
      "decode",
      [](const std::string& name, py::handle actions, py::handle world_T_hand0) {
        const auto representation = make_representation(name);
        const RigidTransform T0 =
            RigidTransform::from_matrix(matrix4_from(world_T_hand0, "world_T_hand0"));
        return array_of(representation->decode_actions(vector_from(actions, "actions"), T0));
      },
      py::arg("representation"), py::arg("actions"), py::arg("world_T_hand0"),
      "The world-frame chunk (K, 4, 4) a built-in's action vector encodes, given the hand now.");

  m.def(
      "so3_exp",
      [](py::handle r) {
        const Eigen::Matrix3d R = Rotation::exp(vector3_from(r, "r")).matrix();
        py::array_t<double> a({3, 3});
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) a.mutable_data()[3 * i + j] = R(i, j);
        return a;
      },
      py::arg("r"), "exp of a rotation vector (3,) -> (3, 3)");
  m.def(
      "so3_log",
      [](py::handle R) {
        const auto a = real_array(R, "R");
        if (a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3) {
          throw ShapeError("R has shape " + shape_of(a) + "; expected (3, 3)");
        }
        require_finite(a.data(), a.size(), "R");
        Eigen::Matrix3d M;
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) M(r, c) = a.data()[3 * r + c];
        return array_of(Eigen::VectorXd(Rotation::from_matrix(M).log()));
      },
      py::arg("R"), "The rotation vector (3,), angle in [0, pi], of a rotation matrix (3, 3).");
  m.def(
      "se3_exp",
      [](py::handle twist) {
        const Eigen::VectorXd v = vector_from(twist, "twist");
        if (v.size() != 6)
          throw ShapeError("twist has shape (" + std::to_string(v.size()) + ",); expected (6,)");
        return array_of(RigidTransform::exp(Twist(v)).matrix());
      },
      py::arg("twist"), "exp of a twist (rho, omega), (6,) -> (4, 4)");
  m.def(
      "se3_log",
      [](py::handle T) {
        return array_of(Eigen::VectorXd(RigidTransform::from_matrix(matrix4_from(T, "T")).log()));
      },
      py::arg("T"), "The twist (rho, omega), |omega| in [0, pi], of a pose (4, 4).");

  m.def(
      "load_demos",
      [](const std::string& path) {
        py::list out;
        for (const sim::Demo& demo : sim::load_demos(path)) out.append(demo_dict(demo));
        return out;
      },
      py::arg("path"),
      "A `handcentric demos` file as a list of {'world_T_hole': (4, 4), 'world_T_hand': (T, 4, "
      "4)}.");
  m.def(
      "training_scenes",
      [](const std::string& path, int history, int chunk) {
        std::vector<Scene> scenes;
        for (const sim::Demo& demo : sim::load_demos(path)) {
          for (Scene& s : sim::training_scenes(demo, history, chunk))
            scenes.push_back(std::move(s));
        }
        const auto n = static_cast<py::ssize_t>(scenes.size());
        py::array_t<double> H({n, py::ssize_t{history + 1}, py::ssize_t{4}, py::ssize_t{4}});
        py::array_t<double> K({n, py::ssize_t{chunk}, py::ssize_t{4}, py::ssize_t{4}});
        const auto points = n ? static_cast<py::ssize_t>(scenes[0].hand_points.size()) : 0;
        py::array_t<double> P({n, points, py::ssize_t{3}});
        for (py::ssize_t i = 0; i < n; ++i) {
          const Scene& s = scenes[static_cast<std::size_t>(i)];
          auto copy = [i](py::array_t<double>& into, const py::array_t<double>& one) {
            const auto per = static_cast<std::size_t>(one.size());
            std::memcpy(into.mutable_data() + per * static_cast<std::size_t>(i), one.data(),
                        per * sizeof(double));
          };
          copy(H, array_of(s.world_T_hand_history));
          copy(K, array_of(s.world_T_hand_chunk));
          copy(P, array_of(s.hand_points));
        }
        py::dict d;
        d["history"] = H;
        d["chunk"] = K;
        d["hand_points"] = P;
        return d;
      },
      py::arg("path"), py::kw_only(), py::arg("history") = 0, py::arg("chunk") = 8,
      "Every control step of every demo in a file, stacked: {'history': (N, H+1, 4, 4), 'chunk': "
      "(N, K, 4, 4), 'hand_points': (N, 2, 3)} (the sim's eye-in-hand points: the hole's "
      "corners in the hand frame).");
}
