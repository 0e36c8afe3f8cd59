#include "options.hpp"

#include <pybind11/stl.h>
#include <algorithm>
#include <cstdlib>
#include <iomanip>
#include <sstream>

#include "arrays.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/props/transport/plugin_protocol.hpp"
#include "observations.hpp"
#include "handcentric/props/observation/hands.hpp"

namespace handcentric::python {
namespace {

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
  return props::parse_groups(names_of(value, "groups"), "groups", props::kPythonSpelling);
}

std::vector<props::View> views_of(py::handle value) {
  return props::parse_views(names_of(value, "views"), "view", props::kPythonSpelling);
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
  if (cases.is_none()) return props::kDefaultCases;
  return bounded_integer(cases, "cases", 1, props::kMaxCases, "handcentric.MAX_CASES");
}

/// detect=: the frequency the case count is set from (props::cases_to_detect); None: none.
std::optional<double> detect_of(py::handle detect, py::handle cases) {
  if (detect.is_none()) return std::nullopt;
  if (!cases.is_none()) {
    throw InvalidArgument("cases=" + std::string(py::str(cases)) +
                          " and detect=" + std::string(py::str(detect)) +
                          " both set the number of cases; give one of them");
  }
  if (py::isinstance<py::bool_>(detect) || !PyNumber_Check(detect.ptr()) ||
      py::isinstance<py::str>(detect)) {
    throw DtypeError("detect must be a frequency in (0, 1), e.g. detect=0.01; got a " +
                     type_name(detect));
  }
  return py::cast<double>(py::float_(py::reinterpret_borrow<py::object>(detect)));
}

}  // namespace

std::optional<int> optional_integer(py::handle value, const char* name, long long low,
                                    long long high, const char* bound) {
  if (value.is_none()) return std::nullopt;
  return bounded_integer(value, name, low, high, bound);
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

int noise_of(py::handle noise) {
  return bounded_integer(noise, "noise", 1, props::kMaxPolicyNoise, "handcentric.MAX_NOISE");
}

/// The largest image side, in pixels, and the most float32 numbers one batch's images may hold
/// (256 MiB): bounds fixed before anything is allocated.
namespace {

constexpr long long kMaxImageSide = 1024;
constexpr long long kMaxImageNumbers = 1LL << 26;

/// workspace=: None, ((x0, y0, z0), (x1, y1, z1)) or six numbers, validated.
std::optional<props::Workspace> workspace_of(py::handle value) {
  if (value.is_none()) return std::nullopt;
  const auto a = real_array(value, "workspace");
  if (a.size() != 6) {
    throw ShapeError("workspace has shape " + shape_of(a) +
                     "; give ((x0, y0, z0), (x1, y1, z1)) in m, e.g. ((-1, -1, 0), (1, 1, 1))");
  }
  props::Workspace box{Eigen::Vector3d(a.data()[0], a.data()[1], a.data()[2]),
                       Eigen::Vector3d(a.data()[3], a.data()[4], a.data()[5])};
  box.validate();
  return box;
}

}  // namespace

std::shared_ptr<const props::CameraRig> camera_rig_of(const Setup& setup,
                                                      std::optional<int> batch_size) {
  if (setup.cameras.is_none()) {
    if (!setup.image_size.is_none() || setup.channels != "rgbd" || setup.floor) {
      throw InvalidArgument(
          "image_size=, channels= and floor= describe the cameras' images, but cameras=None: "
          "pass cameras=(\"eye_in_hand\",) (or \"third_person\") too");
    }
    return nullptr;
  }
  auto rig = std::make_shared<props::CameraRig>();
  rig->views.clear();
  for (const std::string& name : names_of(setup.cameras, "cameras"))
    rig->views.push_back(props::parse_camera_view(name));
  if (!setup.image_size.is_none()) {
    std::vector<py::object> size;
    try {
      size = setup.image_size.cast<std::vector<py::object>>();
    } catch (const py::cast_error&) {
      throw DtypeError("image_size must be (width, height), got a " + type_name(setup.image_size));
    }
    if (size.size() != 2) {
      throw InvalidArgument("image_size must be two numbers (width, height), got " +
                            std::to_string(size.size()) + "; e.g. (64, 48)");
    }
    rig->camera.width = bounded_integer(size[0], "image width", 1, kMaxImageSide, "1024");
    rig->camera.height = bounded_integer(size[1], "image height", 1, kMaxImageSide, "1024");
  }
  rig->channels = props::parse_image_channels(setup.channels);
  rig->floor = setup.floor;
  rig->validate();
  const long long numbers =
      static_cast<long long>(batch_size.value_or(1)) * static_cast<long long>(rig->views.size()) *
      props::channel_count(rig->channels) * rig->camera.width * rig->camera.height;
  if (numbers > kMaxImageNumbers) {
    throw InvalidArgument("batch_size=" + std::to_string(batch_size.value_or(1)) + " with " +
                          std::to_string(rig->views.size()) + " camera(s) of " +
                          std::to_string(rig->camera.width) + " x " +
                          std::to_string(rig->camera.height) + " makes " + std::to_string(numbers) +
                          " numbers of images per batch, above 2**26; use a smaller batch_size "
                          "or image_size");
  }
  return rig;
}

namespace {

// observations=: the data fix the scenes' sizes and names; the callables get the recorded
// extras; a view the data cannot tell apart from the other is audited once.
void with_recorded(CommonOptions& o, RecordedUse use) {
  const props::RecordedObservations& data = *o.audit.observations;
  if (!data.episode.empty() && !use.episodes) {
    throw InvalidArgument("the observations of " + data.source + " carry an 'episode' index (" +
                          std::to_string(data.episodes().size()) +
                          " episodes), which only the closed loop replays: give "
                          "audit_policy(..., episodes=N), or leave 'episode' out");
  }
  const std::vector<std::string> hands = data.hands();
  if (!hands.empty() && !use.hands) {
    std::string named;
    for (const std::string& h : hands) named += (named.empty() ? "\"" : ", \"") + h + "\"";
    throw InvalidArgument("the observations of " + data.source +
                          " record one history per hand: give hands=(" + named + ")");
  }
  if (o.history || o.hand_points || o.world_points || o.chunk) {
    throw InvalidArgument(
        "history=, hand_points=, world_points= and chunk= fix the sizes of "
        "random scenes; with observations= the data's sizes are used: leave "
        "them out");
  }
  const Scene& first = data.scenes.front();
  auto has = [](const auto& named, const std::string& name) {
    return std::any_of(named.begin(), named.end(), [&](const auto& n) { return n.first == name; });
  };
  for (const std::string& name : o.extra_poses) {
    if (!has(first.extra_poses, name))
      throw InvalidArgument("extra_poses names '" + name + "', which the observations of " +
                            data.source + " do not record: add it under \"extra_poses\"");
  }
  for (const std::string& name : o.scalars) {
    if (!has(first.scalars, name))
      throw InvalidArgument("scalars names '" + name + "', which the observations of " +
                            data.source + " do not record: add it under \"scalars\"");
  }
  // The hands' poses reach the policy in history= (hands.hpp), not as extra poses.
  const bool extra_poses = std::any_of(first.extra_poses.begin(), first.extra_poses.end(),
                                       [](const auto& p) { return !props::is_hand_pose(p.first); });
  o.call.extras = o.call.extras || extra_poses || !first.scalars.empty();
  if (!data.has_world_points() && o.audit.views.size() > 1)
    o.audit.views = {props::View::eye_in_hand};
}

}  // namespace

CommonOptions common_options(py::handle groups, py::handle views, py::handle cases,
                             std::uint64_t seed, std::optional<double> tolerance,
                             const std::string& precision, py::handle extra_poses,
                             py::handle scalars, const Setup& setup, RecordedUse use) {
  CommonOptions o;
  o.audit.cases = cases_of(cases);
  o.audit.detect = detect_of(setup.detect, cases);
  if (o.audit.detect)
    o.audit.cases = props::cases_to_detect(*o.audit.detect, props::kPythonSpelling);
  o.audit.groups = groups_of(groups);
  o.audit.views = views_of(views);
  o.audit.seed = seed;
  o.audit.spelling = props::kPythonSpelling;
  o.audit.precision = props::parse_precision(precision, props::kPythonSpelling);
  if (tolerance) {
    if (!(*tolerance > 0.0)) {
      throw InvalidArgument("tolerance must be in (0, 1), got " + std::to_string(*tolerance) +
                            "; or leave it None for the precision's (1e-9 float64, 3.8e-6 "
                            "float32, 2^-7 bfloat16 and float16)");
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
  o.call.cameras = camera_rig_of(setup, o.batch_size);
  o.audit.workspace = workspace_of(setup.workspace);
  o.audit.observations = observations_of(setup.observations);
  if (o.audit.observations) with_recorded(o, use);
  return o;
}

props::ClassifierOptions classifier_for(const CommonOptions& o) {
  props::ClassifierOptions c = props::classifier_options(o.audit);
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

void set_policy_call(CommonOptions& o, props::ClassifierOptions& c, py::handle rng,
                     py::handle reset, py::handle action_format, py::handle state_format,
                     const std::string& caller) {
  const auto layout = [](py::handle value, const char* keyword) {
    if (!py::isinstance<py::str>(value)) {
      throw DtypeError(std::string(keyword) + " must be a pose format name such as \"matrix\" or " +
                       "\"pos_quat_xyzw\", got a " + type_name(value));
    }
    return parse_pose_format(py::str(value), keyword);
  };
  o.call.action_format = layout(action_format, "action_format");
  o.call.state_format = layout(state_format, "state_format");
  if (!rng.is_none() && !py::isinstance<py::str>(rng))
    throw DtypeError("rng must be None or a mode name, got a " + type_name(rng));
  o.call.rng = py::str(py::module_::import("handcentric._rng").attr("check_mode")(rng));
  o.call.rng_seed = o.audit.seed;
  if (!reset.is_none() && !PyCallable_Check(reset.ptr())) {
    throw DtypeError(
        "reset must be None or a callable taking no arguments (e.g. policy.reset), "
        "got a " +
        type_name(reset));
  }
  o.call.reset = py::reinterpret_borrow<py::object>(reset);
  props::PreflightSpelling& say = c.preflight_spelling;
  say.rng = "rng=\"torch\" (or \"numpy\", or \"generator\" for a generator= keyword)";
  say.reset = "reset= (e.g. reset=policy.reset)";
  say.noise = "draw from the noise argument instead";
  say.distribution = caller == "assert_equivariant"
                         ? "mode=\"distribution\" asserts the law, which needs no pairing"
                         : "its in-distribution verdicts stand: they need no pairing";
  say.eval = "policy.eval() (no batch statistics)";
}

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

}  // namespace handcentric::python
