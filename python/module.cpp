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
#include <chrono>
#include <cstdlib>
#include <iomanip>
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
#include "arrays.hpp"
#include "callables.hpp"

namespace handcentric::python {
namespace {

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

/// The largest fixed history length, number of points or chunk length a caller may ask for.
constexpr long long kMaxSceneSize = 64;

int cases_of(py::handle cases) {
  return bounded_integer(cases, "cases", 1, props::kMaxCases, "handcentric.MAX_CASES");
}

int noise_of(py::handle noise) {
  return bounded_integer(noise, "noise", 1, props::kMaxPolicyNoise, "handcentric.MAX_NOISE");
}

/// The keywords every audit takes besides its groups, views, cases and tolerance: how the
/// callable is called (batch_size, array, device), the progress line, and the scene sizes a
/// network with fixed inputs needs (None: the audit's ranges).
struct Setup {
  py::handle batch_size = py::none();
  std::string array = "numpy";
  py::handle device = py::none();
  bool quiet = false;
  py::handle history = py::none(), hand_points = py::none(), world_points = py::none(),
             chunk = py::none();
};

/// The docstring part about Setup's keywords.
constexpr const char* kSetupDoc = R"doc(
Every keyword argument a callable receives: with extra_poses / scalars (names), extra_poses=
{name: (4, 4)} and scalars={name: float}. cases: 1 to MAX_CASES (10**7).
batch_size=B (1 to MAX_BATCH_SIZE): the callables are called on stacked arrays with a leading
batch axis of at most B: history (B, H+1, 4, 4), chunk (B, K, 4, 4), hand_points (B, n, 3),
world_points (B, m, 3), noise (B, d), each extra pose (B, 4, 4) and scalar (B,); they return
(B, a) (a representation's actions or observation) or (B, K, 4, 4) (a policy). Each row must
depend on its own inputs only; then the verdicts are those of batch_size=None (one scene per
call) bit for bit. Scenes of one shape share a batch: history=, hand_points=, world_points=
(third-person view) and chunk= fix the sizes (None: the audit draws them per case).
array="torch" passes float64 torch tensors (on device=, e.g. "cuda"), array="numpy" (default)
NumPy arrays; results may be either, on any device, with or without grad.
A progress line with the time left goes to stderr after 3 s (quiet=True: none). Needs NumPy
(ImportError at once without it); Ctrl-C stops it with KeyboardInterrupt.)doc";

struct CommonOptions {
  props::AuditOptions audit;
  std::vector<std::string> extra_poses, scalars;
  std::optional<int> batch_size;  ///< none: one scene per call
  CallOptions call;
  bool quiet = false;
  std::optional<int> history, hand_points, world_points, chunk;
};

/// An optional integer keyword in [low, high] (None: not given).
std::optional<int> optional_integer(py::handle value, const char* name, long long low,
                                    long long high, const char* bound) {
  if (value.is_none()) return std::nullopt;
  return bounded_integer(value, name, low, high, bound);
}

CommonOptions common_options(py::handle groups, py::handle views, py::handle cases,
                             std::uint64_t seed, std::optional<double> tolerance,
                             const std::string& precision, py::handle extra_poses,
                             py::handle scalars, const Setup& setup) {
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
  o.batch_size = optional_integer(setup.batch_size, "batch_size", 1, props::kMaxBatchSize,
                                  "handcentric.MAX_BATCH_SIZE");
  o.call.stacked = o.batch_size.has_value();
  o.call.arrays = array_kind_of(setup.array, setup.device);
  o.call.extras = !o.extra_poses.empty() || !o.scalars.empty();
  o.quiet = setup.quiet;
  o.history = optional_integer(setup.history, "history", 0, kMaxSceneSize, "64");
  o.hand_points = optional_integer(setup.hand_points, "hand_points", 0, kMaxSceneSize, "64");
  o.world_points = optional_integer(setup.world_points, "world_points", 1, kMaxSceneSize, "64");
  o.chunk = optional_integer(setup.chunk, "chunk", 1, kMaxSceneSize, "64");
  return o;
}

/// Prints "handcentric.audit_policy: 12 of 20 checks, 6.1 s, about 4 s left" on stderr (the
/// same line again on a terminal, a new line at most every 5 s otherwise) once an audit has run
/// for 3 s, and lets a pending Ctrl-C stop it between checks too.
class ProgressLine {
 public:
  ProgressLine(std::string function, bool quiet)
      : function_(std::move(function)), quiet_(quiet), start_(Clock::now()) {
    // HANDCENTRIC_PROGRESS_AFTER=S: print from S seconds on (a test's 0).
    if (const char* after = std::getenv("HANDCENTRIC_PROGRESS_AFTER")) after_ = std::atof(after);
  }
  ~ProgressLine() {
    if (!printed_ || !tty_) return;
    try {
      write("\n");
    } catch (...) {
    }
  }
  void operator()(int done, int total) {
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (quiet_) return;
    const double elapsed = seconds_since(start_);
    if (elapsed < after_ || done <= 0) return;
    if (!printed_) tty_ = py::module_::import("sys").attr("stderr").attr("isatty")().cast<bool>();
    if (printed_ && seconds_since(last_) < (tty_ ? 1.0 : 5.0) && done < total) return;
    const double left = elapsed / done * (total - done);
    std::ostringstream line;
    line.precision(2);
    line << std::fixed << (tty_ ? "\r" : "") << "handcentric." << function_ << ": " << done
         << " of " << total << " checks, " << std::setprecision(1) << elapsed << " s"
         << (done < total ? ", about " + std::to_string(static_cast<long>(left + 0.5)) + " s left"
                          : std::string(", done"))
         << (tty_ ? "   " : "\n");
    write(line.str());
    printed_ = true;
    last_ = Clock::now();
  }

 private:
  using Clock = std::chrono::steady_clock;
  static double seconds_since(Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
  }
  static void write(const std::string& text) {
    py::object err = py::module_::import("sys").attr("stderr");
    err.attr("write")(text);
    err.attr("flush")();
  }
  std::string function_;
  bool quiet_;
  Clock::time_point start_, last_;
  bool printed_ = false, tty_ = false;
  double after_ = 3.0;
};

props::ClassifierOptions classifier_for(const CommonOptions& o) {
  props::ClassifierOptions c = props::classifier_options(o.audit);
  c.float32_advice = "pass precision=\"float32\"";
  props::SceneShape& shape = c.check.shape;
  shape.extra_pose_names = o.extra_poses;
  shape.scalar_names = o.scalars;
  if (o.history) shape.min_history = shape.max_history = *o.history;
  if (o.hand_points) shape.min_hand_points = shape.max_hand_points = *o.hand_points;
  if (o.world_points) shape.min_world_points = shape.max_world_points = *o.world_points;
  if (o.chunk) shape.min_chunk = shape.max_chunk = *o.chunk;
  // Batched calls: prefetch passes ask each check's inputs together (props/batch.hpp).
  c.check.prefetch = o.batch_size.has_value();
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

/// The callables as the checks see them (props/batch.hpp): answers cached, and batched when the
/// caller gave batch_size.
std::shared_ptr<props::BatchedRepresentation> batched_representation(py::object actions,
                                                                     py::object observation,
                                                                     py::object decode,
                                                                     const CommonOptions& o) {
  return std::make_shared<props::BatchedRepresentation>(
      std::make_shared<PythonRepresentation>(std::move(actions), std::move(observation),
                                             std::move(decode), o.call),
      o.batch_size.value_or(1));
}

std::shared_ptr<props::BatchedPolicy> batched_policy(py::object policy, int noise,
                                                     const CommonOptions& o) {
  // One batch's noise is batch_size x noise numbers: bounded, as one array must fit in memory.
  constexpr long long kMaxBatchNumbers = 1LL << 24;
  if (o.batch_size && static_cast<long long>(*o.batch_size) * noise > kMaxBatchNumbers) {
    throw InvalidArgument(
        "batch_size=" + std::to_string(*o.batch_size) + " with noise=" + std::to_string(noise) +
        " makes a noise array of " + std::to_string(static_cast<long long>(*o.batch_size) * noise) +
        " numbers, above 2**24; use batch_size <= " + std::to_string(kMaxBatchNumbers / noise));
  }
  return std::make_shared<props::BatchedPolicy>(
      std::make_shared<PythonPolicy>(std::move(policy), noise, o.call), o.batch_size.value_or(1));
}

py::dict audit(py::object actions, py::object observation, py::handle groups, py::handle views,
               py::handle cases, std::uint64_t seed, std::optional<double> tolerance,
               const std::string& precision, py::object decode, py::handle extra_poses,
               py::handle scalars, const Setup& setup) {
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
      common_options(groups, views, cases, seed, tolerance, precision, extra_poses, scalars, setup);
  auto representation = batched_representation(actions, observation, decode, o);
  props::ClassifierOptions c = classifier_for(o);
  c.observation = representation->has_observation();
  ProgressLine progress("audit", o.quiet);
  c.progress = std::ref(progress);
  const props::Classification result = props::classify_representation(representation, c);
  return json_loads(props::audit_json({result}))["representations"][py::int_(0)];
}

py::dict audit_policy(py::object policy, py::handle groups, py::handle views, py::handle cases,
                      std::uint64_t seed, std::optional<double> tolerance,
                      const std::string& precision, py::handle noise_length, py::handle extra_poses,
                      py::handle scalars, const Setup& setup) {
  require_numpy("audit_policy");
  if (!PyCallable_Check(policy.ptr()))
    throw DtypeError("policy must be callable, got a " + type_name(policy));
  const int noise = noise_of(noise_length);
  const CommonOptions o =
      common_options(groups, views, cases, seed, tolerance, precision, extra_poses, scalars, setup);
  props::ClassifierOptions c = classifier_for(o);
  ProgressLine progress("audit_policy", o.quiet);
  c.progress = std::ref(progress);
  const props::Classification result = props::classify_policy(batched_policy(policy, noise, o), c);
  return json_loads(props::policy_audit_json({result}))["policies"][py::int_(0)];
}

void assert_invariant(py::object fn, const std::string& group, const std::string& component_name,
                      py::object observation, py::handle views, py::handle cases,
                      std::uint64_t seed, std::optional<double> tolerance,
                      const std::string& precision, py::handle extra_poses, py::handle scalars,
                      const Setup& setup) {
  require_numpy("assert_invariant");
  if (!PyCallable_Check(fn.ptr())) throw DtypeError("fn must be callable, got a " + type_name(fn));
  const props::Component component = component_of(component_name);
  const CommonOptions o = common_options(py::str(group), views, cases, seed, tolerance, precision,
                                         extra_poses, scalars, setup);
  props::ClassifierOptions c = classifier_for(o);
  ProgressLine progress("assert_invariant", o.quiet);
  c.progress = std::ref(progress);
  props::Classification result;
  if (component == props::Component::observation) {
    // fn is the observation function; the actions are never asked for.
    auto representation = batched_representation(
        py::cpp_function([](py::args) { return py::none(); }), fn, py::none(), o);
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
    auto representation = batched_representation(fn, observation, py::none(), o);
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
                        py::handle noise_length, py::handle extra_poses, py::handle scalars,
                        const Setup& setup) {
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
                                         extra_poses, scalars, setup);
  props::ClassifierOptions c = classifier_for(o);
  c.in_distribution = mode != "pointwise";
  ProgressLine progress("assert_equivariant", o.quiet);
  c.progress = std::ref(progress);
  const auto python_policy = batched_policy(policy, noise, o);
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
  m.attr("MAX_CASES") = props::kMaxCases;           // cases= above it: ValueError
  m.attr("MAX_NOISE") = props::kMaxPolicyNoise;     // noise= above it: ValueError
  m.attr("MAX_BATCH_SIZE") = props::kMaxBatchSize;  // batch_size= above it: ValueError

  // The keywords of Setup, the same on every audit.
#define HANDCENTRIC_SETUP_PARAMETERS                                              \
  py::handle batch_size, const std::string &array, py::handle device, bool quiet, \
      py::handle history, py::handle hand_points, py::handle world_points, py::handle chunk
#define HANDCENTRIC_SETUP_VALUE \
  Setup{batch_size, array, device, quiet, history, hand_points, world_points, chunk}
#define HANDCENTRIC_SETUP_ARGUMENTS                                                               \
  py::arg("batch_size") = py::none(), py::arg("array") = "numpy", py::arg("device") = py::none(), \
  py::arg("quiet") = false, py::arg("history") = py::none(), py::arg("hand_points") = py::none(), \
  py::arg("world_points") = py::none(), py::arg("chunk") = py::none()

  m.def(
      "audit",
      [](py::object actions, py::object observation, py::handle groups, py::handle views,
         py::handle cases, std::uint64_t seed, std::optional<double> tolerance,
         const std::string& precision, py::object decode, py::handle extra_poses,
         py::handle scalars, HANDCENTRIC_SETUP_PARAMETERS) {
        return audit(std::move(actions), std::move(observation), groups, views, cases, seed,
                     tolerance, precision, std::move(decode), extra_poses, scalars,
                     HANDCENTRIC_SETUP_VALUE);
      },
      py::arg("actions"), py::arg("observation") = py::none(), py::arg("groups") = all_groups,
      py::arg("views") = both_views, py::arg("cases") = props::kDefaultCases, py::arg("seed") = 1,
      py::arg("tolerance") = py::none(), py::arg("precision") = "float64", py::kw_only(),
      py::arg("decode") = py::none(), py::arg("extra_poses") = py::tuple(),
      py::arg("scalars") = py::tuple(), HANDCENTRIC_SETUP_ARGUMENTS,
      (std::string(R"doc(Audit a representation written in Python.

Returns one representation of `handcentric audit --json`.
actions(history, chunk, hand_points, world_points) -> 1-D array, with history (H+1, 4, 4)
(index 0 = T_0, the hand now, then T_-1, ...), chunk (K, 4, 4) = T_1..T_K, hand_points (n, 3)
in the hand frame at T_0, world_points (m, 3) in the world frame; every pose is world_T_hand.
observation(history, hand_points, world_points) -> 1-D array (optional).
decode(actions, history, hand_points, world_points) -> (K, 4, 4) (optional: lets the audit
prove the map injective; always called one scene at a time). The flow components are the
rectified flow's (eq. 5).
)doc") +
       kSetupDoc)
          .c_str());

  m.def(
      "audit_policy",
      [](py::object policy, py::handle groups, py::handle views, py::handle cases,
         std::uint64_t seed, std::optional<double> tolerance, const std::string& precision,
         py::handle noise, py::handle extra_poses, py::handle scalars,
         HANDCENTRIC_SETUP_PARAMETERS) {
        return audit_policy(std::move(policy), groups, views, cases, seed, tolerance, precision,
                            noise, extra_poses, scalars, HANDCENTRIC_SETUP_VALUE);
      },
      py::arg("policy"), py::arg("groups") = all_groups, py::arg("views") = both_views,
      py::arg("cases") = props::kDefaultCases, py::arg("seed") = 1,
      py::arg("tolerance") = py::none(), py::arg("precision") = "float64",
      py::arg("noise") = props::kPolicyNoise, py::kw_only(), py::arg("extra_poses") = py::tuple(),
      py::arg("scalars") = py::tuple(), HANDCENTRIC_SETUP_ARGUMENTS,
      (std::string(R"doc(Audit a whole policy (eq. 4) pointwise and in distribution.

Returns one policy of `audit --json`.
policy(history, hand_points, world_points, noise) -> (K, 4, 4), the world-frame chunk
T_1..T_K; noise is a float64 vector of `noise` standard normals and must be the policy's only
randomness. noise: 1 to MAX_NOISE (65536).
)doc") +
       kSetupDoc)
          .c_str());

  m.def(
      "assert_invariant",
      [](py::object fn, const std::string& group, const std::string& component,
         py::object observation, py::handle views, py::handle cases, std::uint64_t seed,
         std::optional<double> tolerance, const std::string& precision, py::handle extra_poses,
         py::handle scalars, HANDCENTRIC_SETUP_PARAMETERS) {
        assert_invariant(std::move(fn), group, component, std::move(observation), views, cases,
                         seed, tolerance, precision, extra_poses, scalars, HANDCENTRIC_SETUP_VALUE);
      },
      py::arg("fn"), py::arg("group"), py::arg("component") = "actions", py::kw_only(),
      py::arg("observation") = py::none(), py::arg("views") = both_views,
      py::arg("cases") = props::kDefaultCases, py::arg("seed") = 1,
      py::arg("tolerance") = py::none(), py::arg("precision") = "float64",
      py::arg("extra_poses") = py::tuple(), py::arg("scalars") = py::tuple(),
      HANDCENTRIC_SETUP_ARGUMENTS,
      (std::string(R"doc(Raise AssertionError unless `component` is invariant under `group`.

The error carries the shrunk witness.
component "actions": fn is the actions function; "observation": fn is the observation
function; "flow_input" / "flow_target": fn is the actions function, observation= the
observation function, and the rectified flow is checked pointwise and in distribution.
Every view in `views` must hold.
)doc") +
       kSetupDoc)
          .c_str());

  m.def(
      "assert_equivariant",
      [](py::object policy, const std::string& group, const std::string& mode, py::handle views,
         py::handle cases, std::uint64_t seed, std::optional<double> tolerance,
         const std::string& precision, py::handle noise, py::handle extra_poses, py::handle scalars,
         HANDCENTRIC_SETUP_PARAMETERS) {
        assert_equivariant(std::move(policy), group, mode, views, cases, seed, tolerance, precision,
                           noise, extra_poses, scalars, HANDCENTRIC_SETUP_VALUE);
      },
      py::arg("policy"), py::arg("group"), py::kw_only(), py::arg("mode") = "pointwise",
      py::arg("views") = both_views, py::arg("cases") = props::kDefaultCases, py::arg("seed") = 1,
      py::arg("tolerance") = py::none(), py::arg("precision") = "float64",
      py::arg("noise") = props::kPolicyNoise, py::arg("extra_poses") = py::tuple(),
      py::arg("scalars") = py::tuple(), HANDCENTRIC_SETUP_ARGUMENTS,
      (std::string(R"doc(Raise AssertionError unless policy(g o, n) = g policy(o, n) under `group`.

The error carries the shrunk witness.
mode "pointwise" (default: the same noise n for o and g o; Theorem 1's guarantee, which
implies the law's), "distribution" (independent noise: the laws compared) or "both".
Every view in `views` must hold.
)doc") +
       kSetupDoc)
          .c_str());
#undef HANDCENTRIC_SETUP_PARAMETERS
#undef HANDCENTRIC_SETUP_VALUE
#undef HANDCENTRIC_SETUP_ARGUMENTS

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
