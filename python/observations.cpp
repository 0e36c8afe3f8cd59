#include "observations.hpp"

#include <map>
#include <optional>
#include <string>

#include "arrays.hpp"

namespace handcentric::python {
namespace {

constexpr const char* kForm =
    "give dicts with the keys history, chunk, hand_points, world_points, extra_poses, scalars, "
    "held, episode (docs/AUDIT.md, \"Your own observations\")";

props::RecordedPart part_of(py::handle value, const std::string& what) {
  const RealArray a = real_array(value, what);
  props::RecordedPart part;
  for (py::ssize_t d = 0; d < a.ndim(); ++d)
    part.shape.push_back(static_cast<std::int64_t>(a.shape(d)));
  part.values.assign(a.data(), a.data() + a.size());
  // A float32 array (NumPy or torch) stays float32 when handed back to a policy.
  if (py::hasattr(value, "dtype")) {
    const std::string dtype = py::str(value.attr("dtype"));
    part.float32 = dtype == "float32" || dtype == "torch.float32";
  }
  return part;
}

}  // namespace

std::shared_ptr<const props::RecordedObservations> observations_of(py::handle value) {
  if (value.is_none()) return nullptr;
  const py::module_ os = py::module_::import("os");
  if (py::isinstance<py::str>(value) || py::isinstance(value, os.attr("PathLike"))) {
    const std::string path = py::str(os.attr("fspath")(value));
    return std::make_shared<const props::RecordedObservations>(props::read_observations(path));
  }
  if (py::isinstance<py::dict>(value))
    throw DtypeError(
        "observations= is one dict; pass a list of them (one per observation), or a "
        "path to a .jsonl or .npz file");
  py::iterator items;
  try {
    items = py::iter(value);
  } catch (const py::error_already_set&) {
    throw DtypeError("observations= must be a path or an iterable of dicts, got a " +
                     type_name(value) + "; " + kForm);
  }
  std::vector<Scene> scenes;
  std::vector<std::optional<std::int64_t>> episode;
  for (py::handle item : items) {
    const std::string where = "observations[" + std::to_string(scenes.size()) + "]";
    if (static_cast<long long>(scenes.size()) >= kMaxObservations)
      throw InvalidArgument("observations= gave more than " + std::to_string(kMaxObservations) +
                            " items; audit a sample of them");
    if (!py::isinstance<py::dict>(item))
      throw DtypeError(where + " is a " + type_name(item) + ", not a dict; " + kForm);
    std::map<std::string, props::RecordedPart> parts;
    for (const auto& [key_handle, part] : py::reinterpret_borrow<py::dict>(item)) {
      const std::string key = py::str(key_handle);
      // history={hand: (H+1, 4, 4)}: one history per hand ("history/NAME").
      const bool per_hand = key == "history" && py::isinstance<py::dict>(part);
      if (key == "extra_poses" || key == "scalars" || key == "held" || per_hand) {
        if (!py::isinstance<py::dict>(part))
          throw DtypeError(where + "['" + key + "'] must be a dict {name: value}");
        for (const auto& [name, named] : py::reinterpret_borrow<py::dict>(part)) {
          const std::string full = key + "/" + std::string(py::str(name));
          parts[full] =
              part_of(named, where + "['" + key + "']['" + std::string(py::str(name)) + "']");
        }
      } else {
        parts[key] = part_of(part, where + "['" + key + "']");
      }
    }
    episode.push_back(props::episode_of(parts, where));
    scenes.push_back(props::recorded_observation(parts, where));
  }
  std::string source = "a Python iterable";
  return std::make_shared<const props::RecordedObservations>(
      props::recorded_observations(std::move(scenes), std::move(source), episode));
}

}  // namespace handcentric::python
