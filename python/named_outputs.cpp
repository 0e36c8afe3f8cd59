#include "named_outputs.hpp"

#include <set>

namespace handcentric::python {

std::vector<NamedOutput> outputs_from(py::handle outputs, bool need_pose) {
  if (outputs.is_none()) return {};
  if (!py::isinstance<py::dict>(outputs)) {
    throw DtypeError(
        "outputs must be a dict {name: \"pose\" or \"invariant\"}, e.g. "
        "outputs={\"hand\": \"pose\", \"gripper\": \"invariant\"}; got a " +
        type_name(outputs));
  }
  std::vector<NamedOutput> out;
  bool any_pose = false;
  for (auto item : py::reinterpret_borrow<py::dict>(outputs)) {
    if (!py::isinstance<py::str>(item.first))
      throw DtypeError("outputs= has a key that is a " + type_name(item.first) + "; name each");
    NamedOutput output;
    output.name = py::str(item.first);
    const std::string kind = py::isinstance<py::str>(item.second)
                                 ? std::string(py::str(item.second))
                                 : "a " + type_name(item.second);
    if (const auto parsed = props::parse_output_kind(kind)) {
      output.kind = *parsed;
      any_pose = any_pose || *parsed == OutputKind::pose;
    } else {
      throw InvalidArgument("outputs[\"" + output.name + "\"] is '" + kind +
                            "'; an output is \"pose\" (a chunk of world-frame poses, which moves "
                            "with g) or \"invariant\" (numbers that must not change)");
    }
    out.push_back(output);
  }
  if (need_pose && !any_pose) {
    throw InvalidArgument(
        "outputs= names no \"pose\" output; a policy's dict holds its chunk of "
        "poses beside its invariant outputs (e.g. {\"hand\": \"pose\", "
        "\"gripper\": \"invariant\"})");
  }
  return out;
}

py::object output_entry(py::handle result, const std::vector<NamedOutput>& outputs,
                        const std::string& name, const std::string& what) {
  std::string declared;
  for (const NamedOutput& o : outputs) declared += (declared.empty() ? "'" : ", '") + o.name + "'";
  if (!py::isinstance<py::dict>(result)) {
    throw DtypeError(what + " is a " + type_name(result) + "; with outputs= naming " + declared +
                     ", a policy returns a dict of those entries");
  }
  const auto dict = py::reinterpret_borrow<py::dict>(result);
  std::set<std::string> names;
  for (const NamedOutput& o : outputs) names.insert(o.name);
  for (auto item : dict) {
    const std::string key = py::str(item.first);
    if (names.count(key) == 0) {
      throw InvalidArgument(what + " has an entry '" + key +
                            "' that outputs= does not name (it "
                            "names " +
                            declared + "); say what it is: outputs={..., '" + key +
                            "': 'pose' or 'invariant'}");
    }
  }
  for (const NamedOutput& o : outputs) {
    if (!dict.contains(py::str(o.name))) {
      throw InvalidArgument(what + " has no entry '" + o.name +
                            "', which outputs= names; its "
                            "keys are " +
                            std::string(py::str(py::list(dict))));
    }
  }
  return dict[py::str(name)];
}

std::vector<std::vector<RigidTransform>> invariant_as_poses(
    py::handle entry, const std::vector<const Scene*>& observations, bool stacked,
    const std::string& what) {
  const auto a = real_array(entry, what);
  const py::ssize_t rows = stacked ? static_cast<py::ssize_t>(observations.size()) : 1;
  if (stacked && (a.ndim() < 1 || a.shape(0) != rows)) {
    throw ShapeError(what + " has shape " + shape_of(a) + " for a batch of " +
                     std::to_string(rows) + " observations; expected (" + std::to_string(rows) +
                     ", ...), one row per observation");
  }
  const py::ssize_t per_row = a.size() / rows;
  if (per_row < 1) throw ShapeError(what + " has shape " + shape_of(a) + ": no numbers");
  std::vector<std::vector<RigidTransform>> out;
  for (py::ssize_t i = 0; i < rows; ++i) {
    const std::string row = stacked ? what + "[" + std::to_string(i) + "]" : what;
    const double* u = a.data() + i * per_row;
    require_finite(u, per_row, row);
    const RigidTransform& T0 =
        observations[static_cast<std::size_t>(i)]->world_T_hand_history.at(0);
    std::vector<RigidTransform> poses =
        props::invariant_as_poses(u, static_cast<std::size_t>(per_row), T0);
    out.push_back(std::move(poses));
  }
  return out;
}

}  // namespace handcentric::python
