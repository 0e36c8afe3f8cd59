// `import handcentric`: the audit of docs/AUDIT.md, in process, on Python callables and NumPy
// arrays (docs/AUDIT_YOUR_POLICY.md). The callables are wrapped in the library's own
// Representation and NoisyPolicy interfaces, so the checks, tolerances, witnesses and JSON are
// exactly those of `handcentric audit`; only the transport differs from --exec (a function call
// instead of a pipe).
//
// Errors. The checks stop and rethrow a handcentric::Error thrown by the function under test and
// treat any other exception as a counterexample (props/src/checks/check.cpp). A Python exception
// inside a callable is therefore carried through the checks as PythonCallError (a
// handcentric::Error holding the Python exception) and restored, traceback included, once the C++
// call returns. A result of the wrong shape or dtype stops the audit with ShapeError / DtypeError
// naming what was returned and what was expected. The GIL is held throughout: the checks are
// sequential.
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
#include "handcentric/props/checks/check.hpp"
#include "handcentric/props/checks/classifier.hpp"
#include "handcentric/props/transport/plugin_protocol.hpp"
#include "handcentric/props/checks/policy_audit.hpp"
#include "handcentric/props/verdict.hpp"
#include "handcentric/sim/demos.hpp"
#include "arrays.hpp"
#include "closed_loop.hpp"
#include "hands.hpp"
#include "assertions.hpp"
#include "callables.hpp"
#include "options.hpp"
#include "pose_layouts.hpp"
#include "equivariance_profile.hpp"
#include "locate.hpp"

namespace handcentric::python {
namespace {

py::object json_loads(const std::string& text) {
  return py::module_::import("json").attr("loads")(text);
}

/// What the audited callable was shown besides poses: the report says how its images were made.
py::dict cameras_dict(const props::CameraRig& rig) {
  py::list views;
  for (const props::View view : rig.views) views.append(props::to_string(view));
  py::dict d;
  d["views"] = views;
  d["image_size"] = py::make_tuple(rig.camera.width, rig.camera.height);
  d["channels"] = props::to_string(rig.channels);
  d["horizontal_fov_deg"] = rig.camera.horizontal_fov_deg;
  d["max_range_m"] = rig.camera.max_range;
  d["point_radius_m"] = rig.point_radius;
  d["floor"] = rig.floor;
  return d;
}

// What the audit showed the callables besides random scenes: the cameras and the user's data.
void add_inputs(py::dict& report, const CommonOptions& o) {
  if (o.audit.detect) {
    report["detect"] =
        py::dict(py::arg("frequency") = *o.audit.detect, py::arg("cases") = o.audit.cases);
  }
  if (o.call.cameras) report["cameras"] = cameras_dict(*o.call.cameras);
  if (o.audit.observations) {
    report["observations"] = py::dict(py::arg("source") = o.audit.observations->source,
                                      py::arg("count") = o.audit.observations->scenes.size());
  }
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
  CommonOptions o =
      common_options(groups, views, cases, seed, tolerance, precision, extra_poses, scalars, setup);
  ProgressLine progress("audit", o.quiet);
  o.call.asked = [&progress](std::size_t rows) { progress.asked(rows); };
  auto representation = batched_representation(actions, observation, decode, o);
  props::ClassifierOptions c = classifier_for(o);
  c.observation = representation->has_observation();
  c.progress = std::ref(progress);
  const props::Classification result = props::classify_representation(representation, c);
  py::dict report = json_loads(props::audit_json({result}))["representations"][py::int_(0)];
  add_inputs(report, o);
  return report;
}

py::dict audit_policy(py::object policy, py::handle groups, py::handle views, py::handle cases,
                      std::uint64_t seed, std::optional<double> tolerance,
                      const std::string& precision, py::handle noise_length, py::handle extra_poses,
                      py::handle scalars, py::handle rng, py::handle reset,
                      py::handle action_format, py::handle state_format, py::handle outputs,
                      py::handle hands, py::handle episodes, py::handle episode_length,
                      bool test_law, const Setup& setup) {
  require_numpy("audit_policy");
  if (!PyCallable_Check(policy.ptr()))
    throw DtypeError("policy must be callable, got a " + type_name(policy));
  const int noise = noise_of(noise_length);
  CommonOptions o = common_options(groups, views, cases, seed, tolerance, precision, extra_poses,
                                   scalars, setup, {!episodes.is_none(), !hands.is_none()});
  props::ClassifierOptions c = classifier_for(o);
  c.law_from_pointwise = !test_law;
  set_policy_call(o, c, rng, reset, action_format, state_format, "audit_policy");
  ProgressLine progress("audit_policy", o.quiet);
  c.progress = std::ref(progress);
  o.call.asked = [&progress](std::size_t rows) { progress.asked(rows); };
  o.call.outputs = outputs_from(outputs, hands.is_none());
  set_hands(o, c, hands);
  const auto loop = closed_loop_from(episodes, episode_length, o.audit.observations.get());
  if (o.call.outputs.empty()) {
    props::Classification result = props::classify_policy(batched_policy(policy, noise, o), c);
    if (loop) add_closed_loop(result, policy, noise, o, c, *loop);
    py::dict report = json_loads(props::policy_audit_json({result}))["policies"][py::int_(0)];
    add_inputs(report, o);
    return report;
  }
  // Named outputs: each audited as a map of its own (named_outputs.hpp); one report whose checks
  // each carry their `output`, whose summary holds where every output holds, and `outputs`,
  // each output's kind and summary.
  py::dict report, per_output;
  py::list checks;
  for (const NamedOutput& output : o.call.outputs) {
    CommonOptions one = o;
    one.call.output = output.name;
    props::Classification result = props::classify_policy(batched_policy(policy, noise, one), c);
    // The closed loop executes the first pose output and compares this one.
    if (loop) add_closed_loop(result, policy, noise, one, c, *loop);
    py::dict part = json_loads(props::policy_audit_json({result}))["policies"][py::int_(0)];
    for (auto check : part["checks"]) {
      check["output"] = output.name;
      check["kind"] = to_string(output.kind);
      checks.append(check);
    }
    per_output[py::str(output.name)] =
        py::dict(py::arg("kind") = to_string(output.kind), py::arg("summary") = part["summary"]);
    if (report.empty()) {
      report = part;
      report["name"] = "python: " + callable_name(policy);
      // A copy: the merged summary below must leave this output's own summary as it is.
      report["summary"] = py::module_::import("copy").attr("deepcopy")(part["summary"]);
      continue;
    }
    // summary[view][mode][group]: every output's verdict there.
    for (auto view : part["summary"].cast<py::dict>())
      for (auto mode : view.second.cast<py::dict>())
        for (auto group : mode.second.cast<py::dict>()) {
          py::dict merged = report["summary"][view.first][mode.first];
          merged[group.first] = merged[group.first].cast<bool>() && group.second.cast<bool>();
        }
  }
  report["checks"] = checks;
  report["outputs"] = per_output;
  add_inputs(report, o);
  return report;
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
  // A policy that is not a function of its inputs as called (props/preflight.hpp).
  static py::exception<props::StatefulPolicy> stateful_type(m, "StatefulPolicyError",
                                                            error_type.ptr());
  static py::exception<props::BatchCoupling> coupling_type(m, "BatchCouplingError",
                                                           error_type.ptr());
  static py::exception<props::OwnRandomness> randomness_type(m, "OwnRandomnessError",
                                                             error_type.ptr());
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const PythonCallError& e) {
      e.error->restore();  // the callable's own exception, with its traceback
      if (!e.context().empty()) {
        // Where the audit was (the case, its seed, the observation), as a note under the
        // traceback (PEP 678), the exception itself unchanged.
        PyObject *type = nullptr, *value = nullptr, *traceback = nullptr;
        PyErr_Fetch(&type, &value, &traceback);
        PyErr_NormalizeException(&type, &value, &traceback);
        if (value != nullptr && PyObject_HasAttrString(value, "add_note")) {
          PyObject* note = PyUnicode_FromString(("handcentric: " + e.context()).c_str());
          if (note != nullptr) {
            PyObject* done = PyObject_CallMethod(value, "add_note", "O", note);
            Py_XDECREF(done);
            Py_DECREF(note);
          }
          PyErr_Clear();
        }
        PyErr_Restore(type, value, traceback);
      }
    } catch (const ShapeError& e) {
      PyErr_SetString(shape_error_type.ptr(), e.what());
    } catch (const props::StatefulPolicy& e) {
      PyErr_SetString(stateful_type.ptr(), e.what());
    } catch (const props::BatchCoupling& e) {
      PyErr_SetString(coupling_type.ptr(), e.what());
    } catch (const props::OwnRandomness& e) {
      PyErr_SetString(randomness_type.ptr(), e.what());
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
#define HANDCENTRIC_SETUP_PARAMETERS                                                         \
  py::handle batch_size, const std::string &array, py::handle device, bool quiet,            \
      py::handle history, py::handle hand_points, py::handle world_points, py::handle chunk, \
      py::handle cameras, py::handle image_size, const std::string &channels, bool floor,    \
      py::handle workspace, py::handle observations, py::handle detect
#define HANDCENTRIC_SETUP_VALUE                                                                \
  Setup{batch_size, array,      device,   quiet, history,   hand_points,  world_points, chunk, \
        cameras,    image_size, channels, floor, workspace, observations, detect}
#define HANDCENTRIC_SETUP_ARGUMENTS                                                               \
  py::arg("batch_size") = py::none(), py::arg("array") = "numpy", py::arg("device") = py::none(), \
  py::arg("quiet") = false, py::arg("history") = py::none(), py::arg("hand_points") = py::none(), \
  py::arg("world_points") = py::none(), py::arg("chunk") = py::none(),                            \
  py::arg("cameras") = py::none(), py::arg("image_size") = py::none(),                            \
  py::arg("channels") = "rgbd", py::arg("floor") = false, py::arg("workspace") = py::none(),      \
  py::arg("observations") = py::none(), py::arg("detect") = py::none()

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
      py::arg("views") = both_views, py::arg("cases") = py::none(), py::arg("seed") = 1,
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
         py::handle noise, py::handle extra_poses, py::handle scalars, py::handle rng,
         py::handle reset, py::handle action_format, py::handle state_format, py::handle outputs,
         py::handle hands, py::handle episodes, py::handle episode_length, bool test_law,
         HANDCENTRIC_SETUP_PARAMETERS) {
        return audit_policy(std::move(policy), groups, views, cases, seed, tolerance, precision,
                            noise, extra_poses, scalars, rng, reset, action_format, state_format,
                            outputs, hands, episodes, episode_length, test_law,
                            HANDCENTRIC_SETUP_VALUE);
      },
      py::arg("policy"), py::arg("groups") = all_groups, py::arg("views") = both_views,
      py::arg("cases") = py::none(), py::arg("seed") = 1, py::arg("tolerance") = py::none(),
      py::arg("precision") = "float64", py::arg("noise") = props::kPolicyNoise, py::kw_only(),
      py::arg("extra_poses") = py::tuple(), py::arg("scalars") = py::tuple(),
      py::arg("rng") = py::none(), py::arg("reset") = py::none(),
      py::arg("action_format") = "matrix", py::arg("state_format") = "matrix",
      py::arg("outputs") = py::none(), py::arg("hands") = py::none(),
      py::arg("episodes") = py::none(), py::arg("episode_length") = py::none(),
      py::arg("test_law") = false, HANDCENTRIC_SETUP_ARGUMENTS,
      (std::string(R"doc(Audit a whole policy (eq. 4) pointwise and in distribution.

Returns one policy of `audit --json`.
policy(history, hand_points, world_points, noise) -> (K, 4, 4), the world-frame chunk
T_1..T_K; noise is a float64 vector of `noise` standard normals. noise: 1 to MAX_NOISE (65536).
Before any verdict a preflight asks a few observations again (the result's "preflight"): a
policy whose answer depends on earlier calls raises StatefulPolicyError (reset=policy.reset,
called before every call, starts each afresh), one whose rows depend on their batch
BatchCouplingError; one that draws its own random numbers gets no pointwise verdicts unless
rng="torch" / "numpy" / "generator" seeds its draws alike for o and g o (one row per call).
action_format= names the layout of the poses the policy returns, state_format= that of the
poses it is given (history, extra_poses): "matrix" (default, (..., 4, 4)), "pos_quat_xyzw",
"pos_quat_wxyz", "pos_axis_angle", "pos_rot6d_rows", "pos_rot6d_cols", "pos_euler_<axes>"
(SciPy's spelling: lowercase extrinsic, uppercase intrinsic); then the chunk is (K, w) and the
history (H+1, w). outputs={"hand": "pose", "gripper": "invariant"}: the policy returns a dict;
each pose entry must move with g, each invariant entry (numbers of any shape) must not change;
each check of the result carries its "output", and "outputs" gives each one's summary.
hands=("left", "right"): history is a dict {hand: (H+1, 4, 4)} and the policy's dict holds one
chunk per hand, each a "pose" output (verdicts per hand); the hands after the first are drawn
as extra poses "hand:<name>" that move with g, or with observations= as recorded (each
observation's "history" a dict {hand: (H+1, 4, 4)}).
episodes=N, episode_length=T (default 16): closed-loop checks too (mode "closed_loop"): for
each group and view, N episodes, each two rollouts of T steps from o and g o with the same noise,
reset= called once at the start of each (the policy keeps its state through the episode), the
first pose of each answer executed; the executed poses must agree with g step by step. With
observations= whose observations carry an "episode" integer, episodes=N replays the first N
recorded episodes as recorded instead (one g per episode; the hand does not move to the executed
pose; no episode_length=).
Each pointwise case draws its own noise (the same for o and g o), so a policy that passed the
preflight and holds pointwise holds in law too: such a cell's in-distribution verdict says
method "from_pointwise" and asks nothing more. test_law=True runs the in-distribution tests on
every cell.
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
      py::arg("cases") = py::none(), py::arg("seed") = 1, py::arg("tolerance") = py::none(),
      py::arg("precision") = "float64", py::arg("extra_poses") = py::tuple(),
      py::arg("scalars") = py::tuple(), HANDCENTRIC_SETUP_ARGUMENTS,
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
         py::handle rng, py::handle reset, py::handle action_format, py::handle state_format,
         py::handle outputs, py::handle hands, HANDCENTRIC_SETUP_PARAMETERS) {
        assert_equivariant(std::move(policy), group, mode, views, cases, seed, tolerance, precision,
                           noise, extra_poses, scalars, rng, reset, action_format, state_format,
                           outputs, hands, HANDCENTRIC_SETUP_VALUE);
      },
      py::arg("policy"), py::arg("group"), py::kw_only(), py::arg("mode") = "pointwise",
      py::arg("views") = both_views, py::arg("cases") = py::none(), py::arg("seed") = 1,
      py::arg("tolerance") = py::none(), py::arg("precision") = "float64",
      py::arg("noise") = props::kPolicyNoise, py::arg("extra_poses") = py::tuple(),
      py::arg("scalars") = py::tuple(), py::arg("rng") = py::none(), py::arg("reset") = py::none(),
      py::arg("action_format") = "matrix", py::arg("state_format") = "matrix",
      py::arg("outputs") = py::none(), py::arg("hands") = py::none(), HANDCENTRIC_SETUP_ARGUMENTS,
      (std::string(R"doc(Raise AssertionError unless policy(g o, n) = g policy(o, n) under `group`.

The error carries the shrunk witness.
mode "pointwise" (default: the same noise n for o and g o; Theorem 1's guarantee, which
implies the law's), "distribution" (independent noise: the laws compared) or "both".
Every view in `views` must hold, and with outputs= every output. rng=, reset=, action_format=,
state_format=, outputs= and hands= as in audit_policy; a policy that draws its
own random numbers without rng= raises OwnRandomnessError for "pointwise" and "both".
)doc") +
       kSetupDoc)
          .c_str());
  m.def(
      "equivariance_profile",
      [](py::object either, py::object group, py::object policy, py::object representation,
         const std::string& component, py::handle noise, py::object observation, py::handle sizes,
         int scenes, std::uint64_t seed, int samples, const std::string& view,
         HANDCENTRIC_SETUP_PARAMETERS) {
        return equivariance_profile(
            {std::move(either), std::move(policy), std::move(representation)}, std::move(group),
            component, noise, std::move(observation), sizes, scenes, seed, samples, view,
            HANDCENTRIC_SETUP_VALUE);
      },
      py::arg("policy_or_representation") = py::none(), py::arg("group") = py::none(),
      py::kw_only(), py::arg("policy") = py::none(), py::arg("representation") = py::none(),
      py::arg("component") = "actions", py::arg("noise") = py::none(),
      py::arg("observation") = py::none(), py::arg("sizes") = py::none(), py::arg("scenes") = 16,
      py::arg("seed") = 1, py::arg("samples") = 32, py::arg("view") = "eye_in_hand",
      HANDCENTRIC_SETUP_ARGUMENTS,
      (std::string(R"doc(How far from equivariant: the error against the size of g.

Returns one profile of `handcentric audit --profile` (docs/AUDIT.md, "Profiles") as a dict:
sizes (rad for rotation and c8, m for translation, both at once for se2 and se3), in_group,
pointwise {median, max} and distribution (None, or {method, median, max, floor}) per size, each
divided by the chunk's scale, and lie_derivative {median, max, step, method} (the slope at the
identity, Gruver et al. 2023). Pass one map: policy=, a policy(history, hand_points,
world_points, noise) -> (K, 4, 4), with noise= (the length of its noise vector); or
representation=, a built-in's name (REPRESENTATIONS or "actionflow") or a representation's
actions function (component="observation" profiles observation= instead). The positional
policy_or_representation (a policy when noise= is given) still works, with a
DeprecationWarning. sizes=None: the group's grid; scenes: 1 to 10**4 per size; samples: draws
per side of the energy distance. Deterministic given seed, which draws the scenes, the
policy's fixed noise and the laws' samples.
)doc") +
       kSetupDoc)
          .c_str());
  // handcentric.locate's questions (python/handcentric/locate.py); not public on its own.
  m.def(
      "_locate_cases",
      [](py::object policy, py::object on_ask, const std::string& group, const std::string& view,
         py::handle cases, std::uint64_t seed, std::optional<double> tolerance,
         const std::string& precision, py::handle noise, py::handle extra_poses, py::handle scalars,
         py::handle rng, py::handle reset, HANDCENTRIC_SETUP_PARAMETERS) {
        return locate_cases(std::move(policy), std::move(on_ask), group, view, cases, seed,
                            tolerance, precision, noise, extra_poses, scalars, rng, reset,
                            HANDCENTRIC_SETUP_VALUE);
      },
      py::arg("policy"), py::arg("on_ask"), py::kw_only(), py::arg("group") = "se3",
      py::arg("view") = "eye_in_hand", py::arg("cases") = 100, py::arg("seed") = 1,
      py::arg("tolerance") = py::none(), py::arg("precision") = "float64",
      py::arg("noise") = props::kPolicyNoise, py::arg("extra_poses") = py::tuple(),
      py::arg("scalars") = py::tuple(), py::arg("rng") = py::none(), py::arg("reset") = py::none(),
      HANDCENTRIC_SETUP_ARGUMENTS,
      "The audit's pointwise cases asked of a policy for handcentric.locate (python/locate.hpp).");
  m.def(
      "_lie_derivative_cases",
      [](py::object policy, py::object on_ask, const std::string& group, const std::string& view,
         int scenes, std::uint64_t seed, double step, const std::string& precision,
         py::handle noise, py::handle extra_poses, py::handle scalars, py::handle rng,
         py::handle reset, HANDCENTRIC_SETUP_PARAMETERS) {
        return lie_derivative_cases(std::move(policy), std::move(on_ask), group, view, scenes, seed,
                                    step, precision, noise, extra_poses, scalars, rng, reset,
                                    HANDCENTRIC_SETUP_VALUE);
      },
      py::arg("policy"), py::arg("on_ask"), py::kw_only(), py::arg("group") = "se3",
      py::arg("view") = "eye_in_hand", py::arg("scenes") = 16, py::arg("seed") = 1,
      py::arg("step") = 1e-3, py::arg("precision") = "float64",
      py::arg("noise") = props::kPolicyNoise, py::arg("extra_poses") = py::tuple(),
      py::arg("scalars") = py::tuple(), py::arg("rng") = py::none(), py::arg("reset") = py::none(),
      HANDCENTRIC_SETUP_ARGUMENTS,
      "The questions of handcentric.lie_derivatives: the profile's scenes moved by +-step "
      "(python/locate.hpp).");
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
      "render_cameras",
      [](py::handle history, py::handle hand_points, py::handle world_points, py::handle cameras,
         py::handle image_size, const std::string& channels, bool floor, py::dict extra_poses) {
        Setup setup;
        setup.cameras = cameras;
        setup.image_size = image_size;
        setup.channels = channels;
        setup.floor = floor;
        CallOptions call;
        call.cameras = camera_rig_of(setup, std::nullopt);
        Scene scene = scene_from(history, py::none(), hand_points, world_points);
        for (const auto& [name, pose] : extra_poses) {
          const std::string key = py::str(name);
          scene.extra_poses.emplace_back(
              key, RigidTransform::from_matrix(matrix4_from(pose, "extra_poses['" + key + "']")));
        }
        return images_of({&scene}, call);
      },
      py::arg("history"), py::arg("hand_points") = py::none(), py::arg("world_points") = py::none(),
      py::kw_only(), py::arg("cameras") = py::make_tuple("eye_in_hand"),
      py::arg("image_size") = py::none(), py::arg("channels") = "rgbd", py::arg("floor") = false,
      py::arg("extra_poses") = py::dict(),
      R"doc(The images an audit with these cameras hands a policy for one scene.

Returns {camera: (C, h, w) float32}, as audit_policy(..., cameras=...) passes images=: what the
policy saw, e.g. for a witness's scene and g * scene.)doc");
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

  m.def("encode_pose", &encode_pose_array, py::arg("poses"), py::arg("format"),
        "Poses (..., 4, 4) as vectors (..., w) in a pose format (action_format=): "
        "\"pos_quat_xyzw\", \"pos_euler_xyz\", ...");
  m.def("decode_pose", &decode_pose_array, py::arg("vectors"), py::arg("format"),
        "Vectors (..., w) in a pose format as poses (..., 4, 4); ValueError when the numbers "
        "contradict the layout (a quaternion off unit norm, 6D vectors not orthonormal).");
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
