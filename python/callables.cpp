#include "callables.hpp"

#include "hands.hpp"
#include "pose_layouts.hpp"

#include <algorithm>
#include <cstring>
#include <pybind11/stl.h>
#include <utility>

namespace handcentric::python {
namespace {

/// Calls fn; a Python exception, or a signal's pending one, leaves as PythonCallError.
template <class... Args>
py::object call(const py::object& fn, Args&&... args) {
  try {
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    return fn(std::forward<Args>(args)...);
  } catch (py::error_already_set& e) {
    throw PythonCallError(std::move(e));
  }
}

py::dict held_of(const std::vector<const Scene*>& scenes, const CallOptions& options);

/// extra_poses={name: (4, 4) or (B, 4, 4)} and scalars={name: float or (B,)}, when wanted, and
/// images= when the audit has cameras.
py::kwargs extras_kwargs(const std::vector<const Scene*>& scenes, const CallOptions& options) {
  py::kwargs kw;
  if (options.cameras && !scenes.empty()) kw["images"] = images_of(scenes, options);
  if (!scenes.empty() && !scenes.front()->held.empty()) kw["held"] = held_of(scenes, options);
  if (!options.extras || scenes.empty()) return kw;
  py::dict poses, scalars;
  const Scene& first = *scenes.front();
  for (std::size_t i = 0; i < first.extra_poses.size(); ++i) {
    // The other hands' poses go in history= (hands.hpp), not here.
    if (first.extra_poses[i].first.rfind(kHandPosePrefix, 0) == 0) continue;
    poses[py::str(first.extra_poses[i].first)] = for_callable(
        extra_pose_in(scenes, i, options.stacked, options.state_format), options.arrays);
  }
  for (std::size_t i = 0; i < first.scalars.size(); ++i) {
    scalars[py::str(first.scalars[i].first)] =
        options.stacked ? for_callable(stacked_scalar(scenes, i), options.arrays)
                        : py::object(py::float_(first.scalars[i].second));
  }
  kw["extra_poses"] = poses;
  kw["scalars"] = scalars;
  return kw;
}

/// held={name: array} of recorded observations: one scene's in its own shape, or (B, ...)
/// stacked (a batch's scenes share their held shapes: props/batch.hpp's shape key), float32 kept.
py::dict held_of(const std::vector<const Scene*>& scenes, const CallOptions& options) {
  py::dict out;
  const Scene& first = *scenes.front();
  for (std::size_t i = 0; i < first.held.size(); ++i) {
    const HeldArray& a = *first.held[i].second;
    std::vector<py::ssize_t> shape;
    if (options.stacked) shape.push_back(static_cast<py::ssize_t>(scenes.size()));
    for (const std::int64_t size : a.shape) shape.push_back(static_cast<py::ssize_t>(size));
    auto fill = [&](auto* data) {
      for (std::size_t s = 0; s < (options.stacked ? scenes.size() : 1); ++s) {
        const std::vector<double>& values = scenes[s]->held[i].second->values;
        std::copy(values.begin(), values.end(), data + s * a.values.size());
      }
    };
    py::str name(first.held[i].first);
    if (a.float32) {
      py::array_t<float> f(shape);
      fill(f.mutable_data());
      out[name] = for_callable(f, options.arrays);
    } else {
      py::array_t<double> d(shape);
      fill(d.mutable_data());
      out[name] = for_callable(d, options.arrays);
    }
  }
  return out;
}

/// The rows of a stacked result (B, a), B = `rows`.
std::vector<Eigen::VectorXd> rows_of(py::handle result, std::size_t rows, const std::string& what) {
  const auto a = real_array(result, what);
  if (a.ndim() != 2 || a.shape(0) != static_cast<py::ssize_t>(rows)) {
    throw ShapeError(what + " has shape " + shape_of(a) + " for a batch of " +
                     std::to_string(rows) + " scenes; expected (" + std::to_string(rows) +
                     ", n), one row per scene");
  }
  require_finite(a.data(), a.size(), what);
  std::vector<Eigen::VectorXd> out;
  out.reserve(rows);
  for (py::ssize_t i = 0; i < a.shape(0); ++i)
    out.emplace_back(Eigen::Map<const Eigen::VectorXd>(a.data() + i * a.shape(1), a.shape(1)));
  return out;
}

}  // namespace

py::dict images_of(const std::vector<const Scene*>& scenes, const CallOptions& options) {
  const props::CameraRig& rig = *options.cameras;
  const int c = props::channel_count(rig.channels);
  const py::ssize_t h = rig.camera.height, w = rig.camera.width;
  std::vector<py::array_t<float>> arrays;
  for (std::size_t v = 0; v < rig.views.size(); ++v) {
    arrays.push_back(options.stacked ? py::array_t<float>({static_cast<py::ssize_t>(scenes.size()),
                                                           static_cast<py::ssize_t>(c), h, w})
                                     : py::array_t<float>({static_cast<py::ssize_t>(c), h, w}));
  }
  const std::size_t per_image = static_cast<std::size_t>(c) * static_cast<std::size_t>(h * w);
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const std::vector<CameraImage> images = props::render_views(*scenes[i], rig);
    for (std::size_t v = 0; v < images.size(); ++v) {
      const std::vector<float> pixels = props::network_image(images[v], rig.channels);
      std::copy(pixels.begin(), pixels.end(), arrays[v].mutable_data() + i * per_image);
    }
  }
  py::dict out;
  for (std::size_t v = 0; v < rig.views.size(); ++v)
    out[py::str(props::to_string(rig.views[v]))] = for_callable(arrays[v], options.arrays);
  return out;
}

std::string callable_name(const py::object& fn) {
  if (py::hasattr(fn, "__qualname__")) return py::str(fn.attr("__qualname__"));
  return py::str(py::type::handle_of(fn).attr("__qualname__"));
}

PythonRepresentation::PythonRepresentation(py::object actions, py::object observation,
                                           py::object decode, CallOptions options)
    : actions_(std::move(actions)),
      observation_(std::move(observation)),
      decode_(std::move(decode)),
      options_(std::move(options)),
      name_("python: " + callable_name(actions_)) {}

std::vector<Eigen::VectorXd> PythonRepresentation::encode(const py::object& fn, bool with_chunk,
                                                          const std::vector<const Scene*>& scenes,
                                                          const std::string& what) const {
  const ArrayKind& kind = options_.arrays;
  if (options_.asked) options_.asked(scenes.size());
  if (options_.stacked) {
    py::object result = with_chunk ? call(fn, for_callable(stacked_history(scenes), kind),
                                          for_callable(stacked_chunk(scenes), kind),
                                          for_callable(stacked_hand_points(scenes), kind),
                                          for_callable(stacked_world_points(scenes), kind),
                                          **extras_kwargs(scenes, options_))
                                   : call(fn, for_callable(stacked_history(scenes), kind),
                                          for_callable(stacked_hand_points(scenes), kind),
                                          for_callable(stacked_world_points(scenes), kind),
                                          **extras_kwargs(scenes, options_));
    return rows_of(result, scenes.size(), what);
  }
  std::vector<Eigen::VectorXd> out;
  for (const Scene* s : scenes) {
    const std::vector<const Scene*> one = {s};
    py::object result =
        with_chunk
            ? call(fn, for_callable(array_of(s->world_T_hand_history), kind),
                   for_callable(array_of(s->world_T_hand_chunk), kind),
                   for_callable(array_of(s->hand_points), kind),
                   for_callable(array_of(s->world_points), kind), **extras_kwargs(one, options_))
            : call(fn, for_callable(array_of(s->world_T_hand_history), kind),
                   for_callable(array_of(s->hand_points), kind),
                   for_callable(array_of(s->world_points), kind), **extras_kwargs(one, options_));
    out.push_back(vector_from(result, what));
  }
  return out;
}

std::vector<Eigen::VectorXd> PythonRepresentation::encode_actions_batch(
    const std::vector<const Scene*>& scenes) const {
  return encode(actions_, true, scenes, "the result of actions function " + name_);
}

std::vector<Eigen::VectorXd> PythonRepresentation::encode_observation_batch(
    const std::vector<const Scene*>& scenes) const {
  return encode(observation_, false, scenes,
                "the result of observation function " + callable_name(observation_));
}

std::vector<RigidTransform> PythonRepresentation::decode_in_scene(const Eigen::VectorXd& actions,
                                                                  const Scene& observation) const {
  if (!can_decode())
    throw InvalidArgument(name_ + " has no decode function: pass decode= to audit it");
  const ArrayKind& kind = options_.arrays;
  const std::vector<const Scene*> one = {&observation};
  if (options_.asked) options_.asked(1);
  CallOptions single = options_;
  single.stacked = false;
  py::object result =
      call(decode_, for_callable(array_of(actions), kind),
           for_callable(array_of(observation.world_T_hand_history), kind),
           for_callable(array_of(observation.hand_points), kind),
           for_callable(array_of(observation.world_points), kind), **extras_kwargs(one, single));
  return poses_from(result, "the result of decode function " + callable_name(decode_), true,
                    "(K, 4, 4)");
}

PythonPolicy::PythonPolicy(py::object policy, Eigen::Index noise, CallOptions options)
    : policy_(std::move(policy)),
      noise_(noise),
      options_(std::move(options)),
      name_("python: " + callable_name(policy_) +
            (options_.output.empty() ? "" : " output '" + options_.output + "'")) {
  // The preflight watches the global generators of every policy; rng= seeds them per call.
  rng_module_ = py::module_::import("handcentric._rng");
}

void PythonPolicy::watch_draws(bool on) const {
  watching_ = on;
  if (on) draws_.clear();
}

std::optional<std::vector<std::string>> PythonPolicy::last_draws() const {
  return draws_;
}

namespace {

/// The seed of one row's call under rng=: FNV-1a over the audit's seed and the row's noise bytes,
/// so the same noise gives the same draws (o and g o, paired) and other noise other draws (the
/// in-distribution samples, independent).
std::uint64_t row_seed(std::uint64_t base, const Eigen::VectorXd& noise) {
  std::uint64_t h = 1469598103934665603ULL;
  const auto mix = [&h](std::uint64_t bits) {
    for (int b = 0; b < 8; ++b) h = (h ^ ((bits >> (8 * b)) & 0xffU)) * 1099511628211ULL;
  };
  mix(base);
  for (Eigen::Index i = 0; i < noise.size(); ++i) {
    std::uint64_t bits = 0;
    const double x = noise(i);
    std::memcpy(&bits, &x, sizeof(bits));
    mix(bits);
  }
  return h >> 1;  // below 2**63: torch.manual_seed takes it
}

}  // namespace

std::vector<std::vector<RigidTransform>> PythonPolicy::act_batch(
    const std::vector<const Scene*>& observations,
    const std::vector<const Eigen::VectorXd*>& noises) const {
  if (options_.rng.empty() && options_.stacked) return call_once(observations, noises);
  // One scene per call; and under rng= one row per call, each seeded from its own noise, so that
  // the row's draws do not depend on what else shares its batch.
  std::vector<std::vector<RigidTransform>> out;
  for (std::size_t i = 0; i < observations.size(); ++i) {
    auto one = call_once({observations[i]}, {noises[i]});
    out.push_back(std::move(one.front()));
  }
  return out;
}

std::vector<std::vector<RigidTransform>> PythonPolicy::call_once(
    const std::vector<const Scene*>& observations,
    const std::vector<const Eigen::VectorXd*>& noises) const {
  const ArrayKind& kind = options_.arrays;
  if (options_.asked) options_.asked(observations.size());
  if (!options_.reset.is_none()) (void)call(options_.reset);
  py::kwargs seeded;
  if (!options_.rng.empty()) {
    const py::dict extra = rng_module_.attr("seed_before_call")(
        options_.rng, row_seed(options_.rng_seed, *noises.front()), kind.device);
    for (auto item : extra) seeded[item.first] = item.second;
  }
  py::object before;
  if (watching_) before = rng_module_.attr("snapshot")();
  const auto watched = [&](py::object result) {
    if (watching_) {
      for (auto name : rng_module_.attr("advanced")(before)) {
        const std::string n = py::str(name);
        if (std::find(draws_.begin(), draws_.end(), n) == draws_.end()) draws_.push_back(n);
      }
    }
    return result;
  };
  const auto kwargs = [&](const std::vector<const Scene*>& rows) {
    py::kwargs kw = extras_kwargs(rows, options_);
    for (auto item : seeded) kw[item.first] = item.second;
    return kw;
  };
  const std::string what = "the chunk returned by policy " + name_;
  // A (chunk, gripper) tuple or a dict of outputs without outputs=, named as what it is, not as
  // an array NumPy cannot read.
  const auto chunk_only = [&](py::object result) {
    if (py::isinstance<py::tuple>(result) || py::isinstance<py::dict>(result)) {
      const bool dict = py::isinstance<py::dict>(result);
      throw DtypeError(
          what + " is a " + type_name(result) +
          (dict ? " with keys " + std::string(py::str(py::list(result))) +
                      "; say what each entry is: outputs={name: \"pose\" or \"invariant\"}"
                : " of " + std::to_string(py::len(result)) +
                      " items; a policy returns its world-frame chunk alone, " +
                      (options_.stacked ? "(B, K, 4, 4)" : "(K, 4, 4)") +
                      " poses world_T_hand (or pose vectors with action_format=), or a dict of "
                      "named outputs with outputs={name: \"pose\" or \"invariant\"}"));
    }
    return result;
  };
  // The chunks this callable hands the checks, from the policy's result for `rows`.
  const auto chunks = [&](py::object result, const std::vector<const Scene*>& rows) {
    if (options_.outputs.empty()) {
      return chunks_from(chunk_only(std::move(result)), rows.size(), options_.stacked,
                         options_.action_format, what);
    }
    const auto one_output = [&](const NamedOutput& o) {
      const std::string entry_what = what + "['" + o.name + "']";
      const py::object entry = output_entry(result, options_.outputs, o.name, what);
      if (o.kind == OutputKind::invariant)
        return invariant_as_poses(entry, rows, options_.stacked, entry_what);
      return chunks_from(entry, rows.size(), options_.stacked, options_.action_format, entry_what);
    };
    const auto named =
        std::find_if(options_.outputs.begin(), options_.outputs.end(),
                     [&](const NamedOutput& o) { return o.name == options_.output; });
    if (named == options_.outputs.end())
      throw InvalidArgument("no output named '" + options_.output + "' in outputs=");
    std::vector<std::vector<RigidTransform>> out = one_output(*named);
    if (options_.executed_output.empty() || options_.executed_output == options_.output) return out;
    const auto executed =
        std::find_if(options_.outputs.begin(), options_.outputs.end(),
                     [&](const NamedOutput& o) { return o.name == options_.executed_output; });
    if (executed == options_.outputs.end())
      throw InvalidArgument("no output named '" + options_.executed_output + "' in outputs=");
    const std::vector<std::vector<RigidTransform>> moves = one_output(*executed);
    for (std::size_t i = 0; i < out.size(); ++i) {
      if (moves[i].empty()) throw InvalidArgument(what + " has an empty chunk to execute");
      out[i].insert(out[i].begin(), moves[i].front());
    }
    return out;
  };
  if (!options_.stacked) {
    std::vector<std::vector<RigidTransform>> out;
    for (std::size_t i = 0; i < observations.size(); ++i) {
      const Scene& o = *observations[i];
      const std::vector<const Scene*> one = {&o};
      py::object result = watched(call(policy_, history_argument(one, options_),
                                       for_callable(array_of(o.hand_points), kind),
                                       for_callable(array_of(o.world_points), kind),
                                       for_callable(array_of(*noises[i]), kind), **kwargs(one)));
      out.push_back(chunks(std::move(result), one).front());
    }
    return out;
  }
  py::object result =
      watched(call(policy_, history_argument(observations, options_),
                   for_callable(stacked_hand_points(observations), kind),
                   for_callable(stacked_world_points(observations), kind),
                   for_callable(stacked_vectors(noises), kind), **kwargs(observations)));
  return chunks(std::move(result), observations);
}

}  // namespace handcentric::python
