#include "policy_wire.hpp"

#include <algorithm>
#include <set>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "protocol_detail.hpp"

namespace handcentric::props::policy_wire {
namespace {

using protocol_detail::append_name;
using protocol_detail::append_number;

const char* const kRngModes[] = {"torch", "numpy", "generator"};

std::string hello_field(const std::string& answered, const std::string& field,
                        const nlohmann::json& value) {
  return answered + " with a hello whose \"" + field + "\" is " + one_line(value.dump(), 60);
}

PoseFormat read_layout(const nlohmann::json& hello, const char* field,
                       const std::string& answered) {
  if (!hello.contains(field) || hello[field].is_null()) return {};
  if (!hello[field].is_string()) {
    throw PluginError(hello_field(answered, field, hello[field]) +
                      ", not a layout name; e.g. \"pos_quat_xyzw\" (docs/AUDIT.md, \"--exec\")");
  }
  try {
    return parse_pose_format(hello[field].get<std::string>(),
                             std::string("the hello's \"") + field + "\"");
  } catch (const InvalidArgument& e) {
    throw PluginError(answered + " with a hello whose " + e.what());
  }
}

std::vector<NamedOutput> read_declared_outputs(const nlohmann::json& hello,
                                               const std::string& answered) {
  std::vector<NamedOutput> out;
  if (!hello.contains("outputs") || hello["outputs"].is_null()) return out;
  const nlohmann::json& outputs = hello["outputs"];
  const std::string form =
      "; declare {name: \"pose\" or \"invariant\"}, e.g. {\"hand\": "
      "\"pose\", \"gripper\": \"invariant\"}";
  if (!outputs.is_object() || outputs.empty())
    throw PluginError(hello_field(answered, "outputs", outputs) + form);
  for (const auto& [name, kind] : outputs.items()) {
    const auto parsed =
        kind.is_string() ? parse_output_kind(kind.get<std::string>()) : std::nullopt;
    if (name.empty() || !parsed) {
      throw PluginError(answered + " with a hello whose \"outputs\"[\"" + name + "\"] is " +
                        one_line(kind.dump(), 40) +
                        "; an output is \"pose\" (a chunk of world-frame poses, which moves "
                        "with g) or \"invariant\" (numbers that must not change)");
    }
    out.push_back({name, *parsed});
  }
  return out;
}

std::vector<std::string> read_hands(const nlohmann::json& hello, const std::string& answered) {
  std::vector<std::string> hands;
  if (!hello.contains("hands") || hello["hands"].is_null()) return hands;
  const nlohmann::json& value = hello["hands"];
  const std::string form = "; declare two or more distinct names, e.g. [\"left\", \"right\"]";
  if (!value.is_array()) throw PluginError(hello_field(answered, "hands", value) + form);
  for (const auto& hand : value) {
    if (!hand.is_string() || hand.get<std::string>().empty() ||
        std::count(hands.begin(), hands.end(), hand.get<std::string>()) > 0)
      throw PluginError(hello_field(answered, "hands", value) + form);
    hands.push_back(hand.get<std::string>());
  }
  if (hands.size() < 2) throw PluginError(hello_field(answered, "hands", value) + form);
  return hands;
}

// The hello's "stages": a list of {"name", "kind"}, names distinct, kinds "poses" or "features".
std::vector<PipelineStage> read_stages(const nlohmann::json& hello, const std::string& answered) {
  std::vector<PipelineStage> stages;
  if (!hello.contains("stages") || hello["stages"].is_null()) return stages;
  const nlohmann::json& value = hello["stages"];
  const std::string form =
      "; declare the stages in execution order, e.g. [{\"name\": \"to_hand\", \"kind\": "
      "\"features\"}, {\"name\": \"decode\", \"kind\": \"poses\"}]";
  if (!value.is_array() || value.empty())
    throw PluginError(hello_field(answered, "stages", value) + form);
  for (std::size_t i = 0; i < value.size(); ++i) {
    const nlohmann::json& stage = value[i];
    const std::string at = "\"stages\"[" + std::to_string(i) + "]";
    if (!stage.is_object() || !stage.contains("name") || !stage["name"].is_string() ||
        stage["name"].get<std::string>().empty() || !stage.contains("kind")) {
      throw PluginError(answered + " with a hello whose " + at + " is " +
                        one_line(stage.dump(), 60) + form);
    }
    const std::string name = stage["name"].get<std::string>();
    const auto kind = stage["kind"].is_string() ? parse_stage_kind(stage["kind"].get<std::string>())
                                                : std::nullopt;
    if (!kind) {
      throw PluginError(answered + " with a hello whose " + at + " (\"" + name + "\") has kind " +
                        one_line(stage["kind"].dump(), 40) +
                        "; a stage is \"poses\" (world-frame poses, which move with g) or "
                        "\"features\" (numbers that must not change under g)");
    }
    if (std::any_of(stages.begin(), stages.end(),
                    [&](const PipelineStage& s) { return s.name == name; })) {
      throw PluginError(answered + " with a hello whose \"stages\" name \"" + name +
                        "\" twice; give each stage a name of its own");
    }
    stages.push_back({name, *kind});
  }
  return stages;
}

// One pose vector in `format`, the k-th of `field`.
RigidTransform pose_of(const double* v, std::size_t k, const PoseFormat& format,
                       const std::string& field, const std::string& answered) {
  if (format.kind == PoseFormat::Kind::matrix)
    return protocol_detail::pose_from(v, k, answered, field);
  const Eigen::Map<const Eigen::VectorXd> vector(v, format.width());
  try {
    return decode_pose(vector, format, field + "[" + std::to_string(k) + "]");
  } catch (const InvalidArgument& e) {
    throw PluginError(answered + ": " + e.what());
  }
}

// A pose output: K vectors of the layout's width, as lists or one encoded [K, w] array
// ([K, 4, 4] for matrices too).
std::vector<RigidTransform> read_pose_output(const nlohmann::json& value, const PoseFormat& format,
                                             const std::string& field,
                                             const std::string& answered) {
  const std::size_t w = static_cast<std::size_t>(format.width());
  const std::string form = "K >= 1 poses of " + std::to_string(w) + " numbers each (\"" +
                           format.name() + "\", the hello's \"action_format\")";
  std::vector<double> values;
  if (wire::is_encoded(value)) {
    wire::Array array;
    try {
      array = wire::read_array(value, answered + " with " + field);
    } catch (const wire::FormatError& e) {
      throw PluginError(e.what());
    }
    protocol_detail::require_finite(array.values.data(), array.values.size(), field, answered);
    std::size_t per_row = 1;
    for (std::size_t d = 1; d < array.shape.size(); ++d) per_row *= array.shape[d];
    if (array.dtype != wire::Dtype::float64 || array.shape.empty() || array.shape[0] < 1 ||
        per_row != w) {
      throw PluginError(answered + " with " + field + " of an encoded array that is not [K, " +
                        std::to_string(w) + "] float64; " + field + " is " + form);
    }
    values = std::move(array.values);
  } else {
    if (!value.is_array() || value.empty())
      throw PluginError(answered + " with " + field + " that is not a list; it is " + form);
    for (std::size_t k = 0; k < value.size(); ++k) {
      const std::string item = field + "[" + std::to_string(k) + "]";
      const Eigen::VectorXd v = protocol_detail::read_numbers(value[k], item, answered);
      if (static_cast<std::size_t>(v.size()) != w) {
        throw PluginError(answered + " with " + item + " of " + std::to_string(v.size()) +
                          " numbers; " + field + " is " + form);
      }
      values.insert(values.end(), v.data(), v.data() + v.size());
    }
  }
  std::vector<RigidTransform> poses;
  for (std::size_t k = 0; k < values.size() / w; ++k)
    poses.push_back(pose_of(values.data() + k * w, k, format, field, answered));
  return poses;
}

// An invariant output: any nesting of lists of numbers, or one encoded array, flattened.
Eigen::VectorXd read_invariant(const nlohmann::json& value, const std::string& field,
                               const std::string& answered) {
  std::vector<double> numbers;
  if (wire::is_encoded(value)) {
    wire::Array array;
    try {
      array = wire::read_array(value, answered + " with " + field);
    } catch (const wire::FormatError& e) {
      throw PluginError(e.what());
    }
    numbers = std::move(array.values);
  } else {
    const auto walk = [&](const auto& self, const nlohmann::json& v, int depth) -> void {
      if (v.is_number()) {
        numbers.push_back(v.get<double>());
      } else if (v.is_array() && depth < kMaxReplyDepth) {
        for (const auto& item : v) self(self, item, depth + 1);
      } else {
        throw PluginError(answered + " with " + field + " holding " + one_line(v.dump(), 40) +
                          "; an invariant output is numbers (a list, nested lists or an "
                          "encoded array)");
      }
    };
    walk(walk, value, 0);
  }
  if (numbers.empty())
    throw PluginError(answered + " with " + field + " holding no numbers; send at least one");
  protocol_detail::require_finite(numbers.data(), numbers.size(), field, answered);
  return Eigen::Map<const Eigen::VectorXd>(numbers.data(),
                                           static_cast<Eigen::Index>(numbers.size()));
}

// The form of an answer's {name: value} field: "outputs" or "stages".
struct NamedField {
  const char* field;        // "outputs"
  const char* entry;        // "an output": one of them, with its article
  const char* asked;        // what the request asked, said before "without" ("" for outputs)
  const char* declared_as;  // the fix's tail after "declare it in the hello's \"outputs\""
};

// `form`'s field of `answer`, read in the order of `declared` (name, a pose value?): a pose
// value K poses of `format`, any other numbers. Every declared name answered, no other.
std::vector<OutputValue> read_named(const nlohmann::json& answer, const NamedField& form,
                                    const std::vector<std::pair<std::string, bool>>& declared,
                                    const PoseFormat& format, const std::string& answered) {
  const std::string field = form.field, entry = form.entry;
  const std::string noun = entry.substr(entry.find(' ') + 1);  // "output"
  std::string names;
  for (const auto& [name, pose] : declared) names += (names.empty() ? "\"" : ", \"") + name + "\"";
  if (!answer.contains(field) || !answer[field].is_object()) {
    throw PluginError(answered + form.asked + " without \"" + field + "\": {name: value} for the " +
                      field + " its hello declares (" + names + "): '" +
                      one_line(answer.dump(), 120) + "'");
  }
  const nlohmann::json& given = answer[field];
  for (const auto& item : given.items()) {
    if (std::none_of(declared.begin(), declared.end(),
                     [&](const auto& d) { return d.first == item.key(); })) {
      throw PluginError(answered + " with " + entry + " \"" + item.key() +
                        "\" its hello does not declare (it declares " + names +
                        "); declare it in the hello's \"" + field + "\"" + form.declared_as);
    }
  }
  // In the hello's order (for stages, the execution order), whatever the answer's.
  std::vector<OutputValue> out;
  for (const auto& [name, pose] : declared) {
    if (!given.contains(name)) {
      throw PluginError(answered + " without the " + noun + " \"" + name +
                        "\" its hello declares; answer every one of " + names);
    }
    const std::string at = "\"" + field + "\"[\"" + name + "\"]";
    if (pose)
      out.push_back({read_pose_output(given[name], format, at, answered), {}});
    else
      out.push_back({{}, read_invariant(given[name], at, answered)});
  }
  return out;
}

// Poses in the state layout: lists of w numbers, or one encoded [n, w] ([n, 4, 4] for matrices).
void append_layout_poses(std::string& out, const std::vector<RigidTransform>& poses,
                         const PoseFormat& format, NumberEncoding encoding) {
  const std::size_t w = static_cast<std::size_t>(format.width());
  std::vector<double> values;
  values.reserve(w * poses.size());
  for (const RigidTransform& T : poses) {
    const Eigen::VectorXd v = encode_pose(T, format);
    values.insert(values.end(), v.data(), v.data() + v.size());
  }
  if (encoding == NumberEncoding::base64) {
    const std::vector<std::size_t> shape = format.kind == PoseFormat::Kind::matrix
                                               ? std::vector<std::size_t>{poses.size(), 4, 4}
                                               : std::vector<std::size_t>{poses.size(), w};
    wire::append_float64_array(out, shape, values.data());
    return;
  }
  out += '[';
  for (std::size_t i = 0; i < poses.size(); ++i) {
    out += i > 0 ? ", [" : "[";
    for (std::size_t j = 0; j < w; ++j) {
      if (j > 0) out += ", ";
      append_number(out, values[i * w + j]);
    }
    out += ']';
  }
  out += ']';
}

}  // namespace

PolicyInterface read_interface(const nlohmann::json& hello, const std::string& answered) {
  PolicyInterface interface;
  interface.state_format = read_layout(hello, "state_format", answered);
  interface.action_format = read_layout(hello, "action_format", answered);
  interface.hands = read_hands(hello, answered);
  const std::vector<NamedOutput> declared = read_declared_outputs(hello, answered);
  if (!interface.hands.empty() || !declared.empty()) {
    try {
      interface.outputs = outputs_with_hands(interface.hands, declared, "the hello's \"outputs\"");
    } catch (const InvalidArgument& e) {
      throw PluginError(answered + " with " + e.what());
    }
    if (std::none_of(interface.outputs.begin(), interface.outputs.end(),
                     [](const NamedOutput& o) { return o.kind == OutputKind::pose; })) {
      throw PluginError(answered +
                        " with a hello whose \"outputs\" names no \"pose\" output; a policy "
                        "answers its chunk of poses beside its invariant outputs (e.g. "
                        "{\"hand\": \"pose\", \"gripper\": \"invariant\"})");
    }
  }
  if (hello.contains("rng") && !hello["rng"].is_null()) {
    const nlohmann::json& rng = hello["rng"];
    if (!rng.is_string() || std::none_of(std::begin(kRngModes), std::end(kRngModes),
                                         [&](const char* m) { return rng == m; })) {
      throw PluginError(hello_field(answered, "rng", rng) +
                        "; declare the generator it seeds from each request's noise: \"torch\", "
                        "\"numpy\" or \"generator\"");
    }
    interface.rng = rng.get<std::string>();
  }
  if (hello.contains("episodes") && !hello["episodes"].is_null()) {
    if (!hello["episodes"].is_boolean()) {
      throw PluginError(hello_field(answered, "episodes", hello["episodes"]) +
                        ", not true or false");
    }
    interface.episodes = hello["episodes"].get<bool>();
  }
  interface.stages = read_stages(hello, answered);
  return interface;
}

void order_outputs(PolicyInterface& interface, const std::vector<std::string>& names) {
  const auto rank = [&](const NamedOutput& o) {
    const auto hand = std::find(interface.hands.begin(), interface.hands.end(), o.name);
    if (hand != interface.hands.end()) return hand - interface.hands.begin();
    return static_cast<std::ptrdiff_t>(interface.hands.size()) +
           (std::find(names.begin(), names.end(), o.name) - names.begin());
  };
  std::stable_sort(interface.outputs.begin(), interface.outputs.end(),
                   [&](const NamedOutput& a, const NamedOutput& b) { return rank(a) < rank(b); });
}

bool writes_poses(const PolicyInterface& interface) {
  return interface.state_format.kind != PoseFormat::Kind::matrix || !interface.hands.empty();
}

void append_poses(std::string& out, const Scene& scene, const PolicyInterface& interface,
                  NumberEncoding encoding) {
  const PoseFormat& format = interface.state_format;
  out += "\"history\": ";
  if (interface.hands.empty()) {
    append_layout_poses(out, scene.world_T_hand_history, format, encoding);
  } else {
    out += '{';
    for (std::size_t h = 0; h < interface.hands.size(); ++h) {
      if (h > 0) out += ", ";
      append_name(out, interface.hands[h]);
      out += ": ";
      append_layout_poses(
          out, h == 0 ? scene.world_T_hand_history : other_hand_history(scene, interface.hands[h]),
          format, encoding);
    }
    out += '}';
  }
  // The other extra poses, one vector each; the hands' own travel in "history".
  bool first = true;
  for (const auto& [name, pose] : scene.extra_poses) {
    if (!interface.hands.empty() && name.rfind(kHandPosePrefix, 0) == 0) continue;
    out += first ? ", \"extra_poses\": {" : ", ";
    first = false;
    append_name(out, name);
    out += ": ";
    const Eigen::VectorXd v = encode_pose(pose, format);  // 16 row-major numbers for matrix
    if (encoding == NumberEncoding::base64) {
      const std::vector<std::size_t> shape =
          format.kind == PoseFormat::Kind::matrix
              ? std::vector<std::size_t>{4, 4}
              : std::vector<std::size_t>{static_cast<std::size_t>(v.size())};
      wire::append_float64_array(out, shape, v.data());
    } else {
      protocol_detail::append_vector(out, v, NumberEncoding::text);
    }
  }
  if (!first) out += '}';
}

bool reads_outputs(const PolicyInterface& interface) {
  return interface.action_format.kind != PoseFormat::Kind::matrix || interface.named();
}

std::vector<OutputValue> read_outputs(const nlohmann::json& answer,
                                      const PolicyInterface& interface,
                                      const std::string& answered) {
  std::vector<OutputValue> out;
  if (!interface.named()) {
    if (!answer.contains("chunk")) {
      throw PluginError(answered + ", a policy request, without a \"chunk\" of poses: '" +
                        one_line(answer.dump(), 120) + "'");
    }
    out.push_back(
        {read_pose_output(answer["chunk"], interface.action_format, "\"chunk\"", answered), {}});
    return out;
  }
  std::vector<std::pair<std::string, bool>> declared;
  for (const NamedOutput& o : interface.outputs)
    declared.emplace_back(o.name, o.kind == OutputKind::pose);
  return read_named(answer, {"outputs", "an output", "", " as \"pose\" or \"invariant\""}, declared,
                    interface.action_format, answered);
}

std::vector<OutputValue> read_stage_values(const nlohmann::json& answer,
                                           const PolicyInterface& interface,
                                           const std::string& answered) {
  std::vector<std::pair<std::string, bool>> declared;
  for (const PipelineStage& stage : interface.stages)
    declared.emplace_back(stage.name, stage.kind == StageKind::poses);
  return read_named(answer, {"stages", "a stage", ", a request with \"stages\": true,", ""},
                    declared, interface.action_format, answered);
}

}  // namespace handcentric::props::policy_wire

namespace handcentric::props {

std::string to_string(StageKind kind) {
  return kind == StageKind::poses ? "poses" : "features";
}

std::optional<StageKind> parse_stage_kind(const std::string& text) {
  if (text == "poses") return StageKind::poses;
  if (text == "features") return StageKind::features;
  return std::nullopt;
}

std::string describe(const PolicyInterface& interface) {
  if (interface.plain() && interface.hands.empty()) return {};
  std::string out = "the plug-in's hello declares";
  std::string sep = " ";
  if (interface.state_format.kind != PoseFormat::Kind::matrix) {
    out += sep + "state_format " + interface.state_format.name();
    sep = "; ";
  }
  if (interface.action_format.kind != PoseFormat::Kind::matrix) {
    out += sep + "action_format " + interface.action_format.name();
    sep = "; ";
  }
  if (!interface.hands.empty()) {
    out += sep + "hands";
    for (std::size_t h = 0; h < interface.hands.size(); ++h)
      out += (h > 0 ? ", " : " ") + interface.hands[h];
    out += " (each a pose output; the others' histories drawn as hand:<name>)";
    sep = "; ";
  }
  if (interface.named()) {
    out += sep + "outputs";
    for (std::size_t o = 0; o < interface.outputs.size(); ++o) {
      out += (o > 0 ? ", " : " ") + interface.outputs[o].name + " (" +
             to_string(interface.outputs[o].kind) + ")";
    }
    sep = "; ";
  }
  if (!interface.rng.empty()) {
    out += sep + "rng " + interface.rng +
           " (its own draws, seeded from each request's noise: the preflight checks that o asked "
           "twice gets the same answer)";
    sep = "; ";
  }
  if (interface.episodes) {
    out += sep +
           "episodes (it keeps state within a closed-loop episode; every other request is a call "
           "of its own)";
    sep = "; ";
  }
  if (!interface.stages.empty()) {
    out += sep + "stages";
    for (std::size_t s = 0; s < interface.stages.size(); ++s) {
      out += (s > 0 ? ", " : " ") + interface.stages[s].name + " (" +
             to_string(interface.stages[s].kind) + ")";
    }
    out += " (audit --locate decides each)";
  }
  return out;
}

}  // namespace handcentric::props
