#include "hands.hpp"

#include <algorithm>

#include "pose_layouts.hpp"

namespace handcentric::python {

void set_hands(CommonOptions& o, props::ClassifierOptions& c, py::handle hands) {
  if (hands.is_none()) return;
  if (py::isinstance<py::str>(hands) || !py::isinstance<py::sequence>(hands)) {
    throw DtypeError("hands must be a sequence of names, e.g. hands=(\"left\", \"right\"); got " +
                     (py::isinstance<py::str>(hands)
                          ? "the string '" + std::string(py::str(hands)) + "'"
                          : "a " + type_name(hands)));
  }
  std::vector<std::string> names;
  for (auto item : py::reinterpret_borrow<py::sequence>(hands)) {
    if (!py::isinstance<py::str>(item))
      throw DtypeError("hands= holds a " + type_name(item) + "; each hand is a name");
    const std::string name = py::str(item);
    if (name.empty() || std::count(names.begin(), names.end(), name) > 0)
      throw InvalidArgument("hands= names '" + name + "' twice or empty; name each hand once");
    names.push_back(name);
  }
  if (names.size() < 2) {
    throw InvalidArgument("hands= names " + std::to_string(names.size()) +
                          " hand; with one hand leave hands= out (its history is an array)");
  }
  o.call.hands = names;
  if (o.audit.observations) {
    // Every hand's history as recorded, the first hand's the scenes' own.
    o.audit.observations = std::make_shared<const props::RecordedObservations>(
        props::recorded_with_hands(*o.audit.observations, names));
    c.check.shape.recorded = o.audit.observations;
    o.call.hands_recorded = true;
  } else {
    for (std::size_t h = 1; h < names.size(); ++h)
      c.check.shape.extra_pose_names.push_back(kHandPosePrefix + names[h]);
  }
  // Each hand a pose output, first; the rest of outputs= after them.
  std::vector<NamedOutput> outputs;
  for (const std::string& hand : names) outputs.push_back({hand, OutputKind::pose});
  for (const NamedOutput& declared : o.call.outputs) {
    const bool is_hand = std::count(names.begin(), names.end(), declared.name) > 0;
    if (is_hand && declared.kind != OutputKind::pose) {
      throw InvalidArgument("outputs[\"" + declared.name + "\"] is '" + to_string(declared.kind) +
                            "', but '" + declared.name + "' is a hand: its chunk is a \"pose\"");
    }
    if (!is_hand) outputs.push_back(declared);
  }
  o.call.outputs = outputs;
}

py::object history_argument(const std::vector<const Scene*>& rows, const CallOptions& options) {
  const ArrayKind& kind = options.arrays;
  if (options.hands.empty())
    return for_callable(history_in(rows, options.stacked, options.state_format), kind);
  py::dict out;
  out[py::str(options.hands.front())] =
      for_callable(history_in(rows, options.stacked, options.state_format), kind);
  for (std::size_t h = 1; h < options.hands.size(); ++h) {
    // Scenes whose history is this hand's: as recorded, or S_k = S_0 T_0^-1 T_k (hands.hpp).
    std::vector<Scene> moved(rows.size());
    for (std::size_t r = 0; r < rows.size(); ++r) {
      moved[r].world_T_hand_history = options.hands_recorded
                                          ? props::recorded_hand_history(*rows[r], options.hands[h])
                                          : props::other_hand_history(*rows[r], options.hands[h]);
    }
    std::vector<const Scene*> pointers;
    for (const Scene& m : moved) pointers.push_back(&m);
    out[py::str(options.hands[h])] =
        for_callable(history_in(pointers, options.stacked, options.state_format), kind);
  }
  return out;
}

}  // namespace handcentric::python
