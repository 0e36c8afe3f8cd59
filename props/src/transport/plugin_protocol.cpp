#include "handcentric/props/transport/plugin_protocol.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <set>
#include <nlohmann/json.hpp>

#include "handcentric/core/format.hpp"
#include "handcentric/props/transport/batch.hpp"
#include "handcentric/props/tolerance.hpp"
#include "../wire_arrays.hpp"
#include "protocol_detail.hpp"
#include "policy_wire.hpp"

namespace handcentric::props {
// Shared with policy_wire.cpp through protocol_detail.hpp (a named namespace: the unity build
// puts both files in one translation unit).
namespace protocol_detail {

// The shortest text that reads back as the same double (std::to_chars): exact like "%.17g", and
// several times faster, which matters when each request carries hundreds of numbers.
void append_number(std::string& out, double value) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof(text), value).ptr;
  out.append(text, end);
}

void append_matrix(std::string& out, const RigidTransform& T) {
  const Eigen::Matrix4d M = T.matrix();
  out += '[';
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      if (r + c > 0) out += ", ";
      append_number(out, M(r, c));
    }
  }
  out += ']';
}

void append_poses(std::string& out, const std::vector<RigidTransform>& poses) {
  out += '[';
  for (std::size_t i = 0; i < poses.size(); ++i) {
    if (i > 0) out += ", ";
    append_matrix(out, poses[i]);
  }
  out += ']';
}

void append_points(std::string& out, const std::vector<Eigen::Vector3d>& points) {
  out += '[';
  for (std::size_t i = 0; i < points.size(); ++i) {
    out += i > 0 ? ", [" : "[";
    for (int j = 0; j < 3; ++j) {
      if (j > 0) out += ", ";
      append_number(out, points[i](j));
    }
    out += ']';
  }
  out += ']';
}

// Poses as one encoded array [n, 4, 4], each matrix row-major (the numbers of append_poses).
void append_encoded_poses(std::string& out, const std::vector<RigidTransform>& poses) {
  std::vector<double> values(16 * poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(values.data() + 16 * i) =
        poses[i].matrix();
  }
  wire::append_float64_array(out, {poses.size(), 4, 4}, values.data());
}

void append_encoded_points(std::string& out, const std::vector<Eigen::Vector3d>& points) {
  std::vector<double> values(3 * points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    Eigen::Map<Eigen::Vector3d>(values.data() + 3 * i) = points[i];
  wire::append_float64_array(out, {points.size(), 3}, values.data());
}

void append_vector(std::string& out, const Eigen::VectorXd& v) {
  out += '[';
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (i > 0) out += ", ";
    append_number(out, v(i));
  }
  out += ']';
}

// A JSON string literal of a name (names come from the plug-in's hello or the command line).
void append_name(std::string& out, const std::string& name) {
  out += nlohmann::json(name).dump();
}

void append_poses(std::string& out, const std::vector<RigidTransform>& poses,
                  NumberEncoding encoding) {
  if (encoding == NumberEncoding::base64)
    append_encoded_poses(out, poses);
  else
    append_poses(out, poses);
}

void append_points(std::string& out, const std::vector<Eigen::Vector3d>& points,
                   NumberEncoding encoding) {
  if (encoding == NumberEncoding::base64)
    append_encoded_points(out, points);
  else
    append_points(out, points);
}

void append_vector(std::string& out, const Eigen::VectorXd& v, NumberEncoding encoding) {
  if (encoding == NumberEncoding::base64)
    wire::append_float64_array(out, {static_cast<std::size_t>(v.size())}, v.data());
  else
    append_vector(out, v);
}

// History, points and extras: what every request carries. Scalars stay JSON numbers in every
// encoding (one number each).
void append_observation(std::string& out, const Scene& scene, NumberEncoding encoding,
                        const PolicyInterface* interface = nullptr) {
  // A policy's own layout or hands: its history and extra poses as it declared them.
  const bool as_declared = interface != nullptr && policy_wire::writes_poses(*interface);
  if (as_declared) {
    policy_wire::append_poses(out, scene, *interface, encoding);
  } else {
    out += "\"history\": ";
    append_poses(out, scene.world_T_hand_history, encoding);
  }
  out += ", \"hand_points\": ";
  append_points(out, scene.hand_points, encoding);
  out += ", \"world_points\": ";
  append_points(out, scene.world_points, encoding);
  if (!scene.extra_poses.empty() && !as_declared) {
    out += ", \"extra_poses\": {";
    for (std::size_t i = 0; i < scene.extra_poses.size(); ++i) {
      if (i > 0) out += ", ";
      append_name(out, scene.extra_poses[i].first);
      out += ": ";
      if (encoding == NumberEncoding::base64) {
        const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> M = scene.extra_poses[i].second.matrix();
        wire::append_float64_array(out, {4, 4}, M.data());
      } else {
        append_matrix(out, scene.extra_poses[i].second);
      }
    }
    out += '}';
  }
  if (!scene.scalars.empty()) {
    out += ", \"scalars\": {";
    for (std::size_t i = 0; i < scene.scalars.size(); ++i) {
      if (i > 0) out += ", ";
      append_name(out, scene.scalars[i].first);
      out += ": ";
      append_number(out, scene.scalars[i].second);
    }
    out += '}';
  }
  // Held arrays (a dataset's images) always travel encoded, in their own dtype: as JSON numbers
  // an image would be several times its size.
  if (!scene.held.empty()) {
    out += ", \"held\": {";
    for (std::size_t i = 0; i < scene.held.size(); ++i) {
      if (i > 0) out += ", ";
      append_name(out, scene.held[i].first);
      out += ": ";
      const HeldArray& array = *scene.held[i].second;
      const std::vector<std::size_t> shape(array.shape.begin(), array.shape.end());
      if (array.float32) {
        const std::vector<float> narrow(array.values.begin(), array.values.end());
        wire::append_float32_array(out, shape, narrow.data());
      } else {
        wire::append_float64_array(out, shape, array.values.data());
      }
    }
    out += '}';
  }
}

std::string reply_to(const std::string& who, int id) {
  return who + " answered request " + std::to_string(id);
}

void require_finite(const double* values, std::size_t count, const std::string& field,
                    const std::string& answered) {
  for (std::size_t i = 0; i < count; ++i) {
    if (!std::isfinite(values[i])) {
      throw PluginError(answered + " with a non-finite \"" + field + "\"[" + std::to_string(i) +
                        "] = " + format_number(values[i]) + "; send finite numbers only");
    }
  }
}

// An encoded array of finite float64 numbers, of `rank` dimensions (`form` names the shape
// expected, for the message).
wire::Array read_encoded(const nlohmann::json& value, const std::string& field, std::size_t rank,
                         const std::string& form, const std::string& answered) {
  const std::string where = answered + " with \"" + field + "\"";
  wire::Array array;
  try {
    array = wire::read_array(value, where);
  } catch (const wire::FormatError& e) {
    throw PluginError(e.what());  // the plug-in's answer, not a file, is at fault
  }
  if (array.dtype != wire::Dtype::float64) {
    throw PluginError(where + " of dtype " + wire::dtype_name(array.dtype) +
                      "; the protocol's numbers are float64 (NumPy: array.astype('<f8'), exact "
                      "from float32)");
  }
  if (array.shape.size() != rank) {
    std::string shape;
    for (std::size_t d : array.shape) shape += (shape.empty() ? "" : ", ") + std::to_string(d);
    throw PluginError(where + " of shape [" + shape + "]; \"" + field + "\" has shape " + form);
  }
  require_finite(array.values.data(), array.values.size(), field, answered);
  return array;
}

// `answered`: "plug-in 'X' answered request n" (and the item of a batch), for messages.
Eigen::VectorXd read_numbers(const nlohmann::json& value, const std::string& field,
                             const std::string& answered) {
  if (wire::is_encoded(value)) {
    const wire::Array array =
        read_encoded(value, field, 1, "[n], one row of numbers (reshape(-1))", answered);
    return Eigen::Map<const Eigen::VectorXd>(array.values.data(),
                                             static_cast<Eigen::Index>(array.values.size()));
  }
  if (!value.is_array())
    throw PluginError(answered + " with \"" + field + "\" that is not an array of numbers");
  Eigen::VectorXd v(static_cast<Eigen::Index>(value.size()));
  for (std::size_t i = 0; i < value.size(); ++i) {
    if (!value[i].is_number()) {
      throw PluginError(answered + " with \"" + field + "\"[" + std::to_string(i) +
                        "] = " + one_line(value[i].dump(), 40) + ", not a number");
    }
    v(static_cast<Eigen::Index>(i)) = value[i].get<double>();
  }
  require_finite(v.data(), value.size(), field, answered);
  return v;
}

std::vector<std::string> read_names(const nlohmann::json& hello, const char* field, int id,
                                    const std::string& who) {
  std::vector<std::string> names;
  if (!hello.contains(field) || hello[field].is_null()) return names;
  if (!hello[field].is_array())
    throw PluginError(reply_to(who, id) + " with a hello whose \"" + field +
                      "\" is not a list of names");
  for (const auto& name : hello[field]) {
    if (!name.is_string() || name.get<std::string>().empty()) {
      throw PluginError(reply_to(who, id) + " with a hello whose \"" + field + "\" holds " +
                        one_line(name.dump(), 40) + ", not a name");
    }
    names.push_back(name.get<std::string>());
  }
  return names;
}

bool read_flag(const nlohmann::json& hello, const char* field, int id, const std::string& who) {
  if (!hello.contains(field) || hello[field].is_null()) return false;
  if (!hello[field].is_boolean())
    throw PluginError(reply_to(who, id) + " with a hello whose \"" + field +
                      "\" is not true or false");
  return hello[field].get<bool>();
}

// A world-frame pose: 16 finite numbers, row-major, last row 0 0 0 1 and a rotation block within
// kOutputPoseTolerance of a rotation. The block is then taken as it is (a float32 plug-in's is
// orthonormal to ~1e-7 only); distances compare it.
RigidTransform pose_from(const double* v, std::size_t k, const std::string& answered,
                         const std::string& field) {
  if (v[12] != 0.0 || v[13] != 0.0 || v[14] != 0.0 || v[15] != 1.0) {
    throw PluginError(answered + " with " + field + "[" + std::to_string(k) +
                      "] that is not a 4x4 pose (16 numbers, row-major, last row 0 0 0 1)");
  }
  const Eigen::Matrix4d M = Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(v);
  if (const std::string defect = pose_defect(M); !defect.empty()) {
    throw PluginError(answered + " with " + field + "[" + std::to_string(k) + "] " +
                      format_matrix(M) + ": " + defect +
                      "; answer world_T_hand poses [[R, p], [0, 0, 0, 1]]");
  }
  return RigidTransform::unchecked(M.topLeftCorner<3, 3>(), M.topRightCorner<3, 1>());
}

RigidTransform read_pose(const nlohmann::json& value, std::size_t k, const std::string& answered) {
  const Eigen::VectorXd v = read_numbers(value, "chunk[" + std::to_string(k) + "]", answered);
  if (v.size() != 16) {
    const bool layout = v.size() == 6 || v.size() == 7 || v.size() == 9;
    throw PluginError(answered + " with \"chunk\"[" + std::to_string(k) + "] of " +
                      std::to_string(v.size()) +
                      " numbers, not a 4x4 pose (16 numbers, row-major, last row 0 0 0 1)" +
                      (layout ? "; a pose of " + std::to_string(v.size()) +
                                    " numbers is a layout: declare it in the hello, e.g. "
                                    "\"action_format\": \"pos_quat_xyzw\" (docs/AUDIT.md, "
                                    "\"--exec\")"
                              : std::string()));
  }
  return pose_from(v.data(), k, answered, "\"chunk\"");
}

// A decode or policy answer's chunk: a list of poses, or an encoded [K, 4, 4] array; empty when
// it has no pose (the caller says what was asked).
std::vector<RigidTransform> read_chunk(const nlohmann::json& value, const std::string& answered) {
  std::vector<RigidTransform> chunk;
  if (wire::is_encoded(value)) {
    const wire::Array array =
        read_encoded(value, "chunk", 3, "[K, 4, 4], K >= 1 world_T_hand poses", answered);
    if (array.shape[1] != 4 || array.shape[2] != 4) {
      throw PluginError(answered + " with \"chunk\" of shape [" + std::to_string(array.shape[0]) +
                        ", " + std::to_string(array.shape[1]) + ", " +
                        std::to_string(array.shape[2]) +
                        "]; \"chunk\" has shape [K, 4, 4], K >= 1 world_T_hand poses");
    }
    for (std::size_t k = 0; k < array.shape[0]; ++k)
      chunk.push_back(pose_from(array.values.data() + 16 * k, k, answered, "\"chunk\""));
    return chunk;
  }
  if (!value.is_array()) return chunk;
  for (std::size_t k = 0; k < value.size(); ++k) chunk.push_back(read_pose(value[k], k, answered));
  return chunk;
}

}  // namespace protocol_detail

using namespace protocol_detail;

void require_distinct_names(const std::vector<std::string>& names, const std::string& flag) {
  std::set<std::string> seen;
  for (const std::string& name : names) {
    if (name.empty() || !seen.insert(name).second) {
      throw InvalidArgument(flag + " needs distinct, non-empty names, got '" + name + "' " +
                            (name.empty() ? "(empty)" : "twice") + "; e.g. " + flag +
                            " start,left_hand");
    }
  }
}

std::vector<std::string> merged_names(std::vector<std::string> first,
                                      const std::vector<std::string>& second) {
  for (const std::string& name : second) {
    if (std::find(first.begin(), first.end(), name) == first.end()) first.push_back(name);
  }
  return first;
}

Scene with_named_extras(Scene scene, const std::vector<std::string>& pose_names,
                        const std::vector<std::string>& scalar_names) {
  auto has = [](const auto& named, const std::string& name) {
    return std::any_of(named.begin(), named.end(),
                       [&name](const auto& entry) { return entry.first == name; });
  };
  for (const std::string& name : pose_names) {
    if (!has(scene.extra_poses, name))
      scene.extra_poses.emplace_back(name, RigidTransform::identity());
  }
  for (const std::string& name : scalar_names) {
    if (!has(scene.scalars, name)) scene.scalars.emplace_back(name, 0.0);
  }
  return scene;
}

std::string encode_request_body(const Scene& scene, const std::optional<FlowQuery>& flow,
                                NumberEncoding encoding) {
  if (flow) encoding = NumberEncoding::text;  // flow requests are single lines
  std::string out;
  append_observation(out, scene, encoding);
  out += ", \"chunk\": ";
  append_poses(out, scene.world_T_hand_chunk, encoding);
  if (flow) {
    out += ", \"eps\": ";
    append_vector(out, *flow->eps);
    out += ", \"t\": ";
    append_number(out, flow->t);
  }
  return out;
}

std::string decode_request_body(const Eigen::VectorXd& actions, const Scene& observation) {
  std::string out = "\"decode\": ";
  append_vector(out, actions);
  out += ", ";
  append_observation(out, observation, NumberEncoding::text);
  return out;
}

std::string policy_request_body(const Scene& observation, const Eigen::VectorXd& noise,
                                NumberEncoding encoding, const PolicyInterface* interface,
                                const EpisodeStep* episode) {
  std::string out;
  append_observation(out, observation, encoding, interface);
  out += ", \"noise\": ";
  append_vector(out, noise, encoding);
  if (episode != nullptr) {
    out += ", \"episode\": {\"index\": " + std::to_string(episode->index) +
           ", \"step\": " + std::to_string(episode->step) + "}";
  }
  return out;
}

std::string batch_request_body(const std::vector<std::string>& bodies, NumberEncoding encoding) {
  std::size_t size = 48;
  for (const std::string& body : bodies) size += body.size() + 4;
  std::string out;
  out.reserve(size);
  if (encoding == NumberEncoding::base64) out += "\"encoding\": \"base64\", ";
  out += "\"batch\": [";
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    out += i > 0 ? ", {" : "{";
    out += bodies[i];
    out += '}';
  }
  out += ']';
  return out;
}

std::string scene_key(const Scene& scene, bool with_chunk) {
  std::string out;
  auto put = [&out](const void* x, std::size_t bytes) {
    out.append(static_cast<const char*>(x), bytes);
  };
  auto put_count = [&put](std::size_t n) { put(&n, sizeof(n)); };
  auto put_pose = [&put](const RigidTransform& T) {
    put(T.rotation().matrix().data(), 9 * sizeof(double));
    put(T.translation().data(), 3 * sizeof(double));
  };
  // Every list with its length first, every name with its length: no two scenes share a key.
  const std::vector<RigidTransform> none;
  for (const auto* poses :
       {&scene.world_T_hand_history, with_chunk ? &scene.world_T_hand_chunk : &none}) {
    put_count(poses->size());
    for (const auto& T : *poses) put_pose(T);
  }
  for (const auto* points : {&scene.hand_points, &scene.world_points}) {
    put_count(points->size());
    for (const auto& x : *points) put(x.data(), 3 * sizeof(double));
  }
  put_count(scene.extra_poses.size());
  for (const auto& [name, T] : scene.extra_poses) {
    put_count(name.size());
    out += name;
    put_pose(T);
  }
  put_count(scene.scalars.size());
  for (const auto& [name, value] : scene.scalars) {
    put_count(name.size());
    out += name;
    put(&value, sizeof(value));
  }
  return out;
}

std::string request_line(int id, const std::string& body) {
  return "{\"id\": " + std::to_string(id) + ", \"protocol\": " + std::to_string(kProtocolVersion) +
         ", " + body + "}\n";
}

namespace {

// The reply line as JSON, with the id of request `id`.
nlohmann::json parse_line(const std::string& line, int id, const std::string& who) {
  // Nesting first, outside strings: a parser recursing into 10^6 brackets would overflow the stack.
  int depth = 0, deepest = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (in_string) {
      if (c == '\\')
        ++i;
      else if (c == '"')
        in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
      if (deepest > kMaxReplyDepth) {
        throw PluginError(reply_to(who, id) + " with JSON nested deeper than " +
                          std::to_string(kMaxReplyDepth) + " levels; an answer needs 3");
      }
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(line);
  } catch (const nlohmann::json::exception& e) {
    // JSON has no NaN or Infinity; Python's json module writes them anyway, and 1e999 overflows.
    const bool non_finite = line.find("NaN") != std::string::npos ||
                            line.find("Infinity") != std::string::npos ||
                            std::string(e.what()).find("overflow") != std::string::npos;
    throw PluginError(
        reply_to(who, id) +
        (non_finite
             ? " with a non-finite number (NaN, Infinity or an overflow, e.g. 1e999 -> inf), "
               "which is not JSON; send finite numbers only: "
             : " with a line that is not JSON: ") +
        "'" + one_line(line, 120) + "'");
  }
  if (!json.is_object() || !json.contains("id")) {
    throw PluginError(reply_to(who, id) + " without an \"id\": '" + one_line(line, 120) + "'");
  }
  if (!json["id"].is_number_integer() || json["id"].get<long long>() != id) {
    throw PluginError(reply_to(who, id) + " with id " + one_line(json["id"].dump(), 40) +
                      "; answer each request, in order, with its own id");
  }
  return json;
}

// The fields of one answer (a whole reply, or one item of a batched one) for a request of `kind`;
// `answered` begins each message, which quotes the line (`line`), or else the item, written out
// only then: a batch's items are not formatted again on the way in.
PluginReply read_answer(const nlohmann::json& json, RequestKind kind, const std::string& answered,
                        const std::string* line, const PolicyInterface* interface);

// A policy_stages answer: the policy's answer, and its stages under `interface`.
PluginReply read_staged_answer(const nlohmann::json& json, const std::string& answered,
                               const std::string* line, const PolicyInterface* interface) {
  if (interface == nullptr || interface->stages.empty()) {
    throw PluginError(answered +
                      ": stages were asked of a plug-in whose hello declares no "
                      "\"stages\"");
  }
  PluginReply reply = read_answer(json, RequestKind::policy, answered, line, interface);
  reply.stages = policy_wire::read_stage_values(json, *interface, answered);
  return reply;
}

PluginReply read_answer(const nlohmann::json& json, RequestKind kind, const std::string& answered,
                        const std::string* line, const PolicyInterface* interface) {
  if (kind == RequestKind::policy_stages)
    return read_staged_answer(json, answered, line, interface);
  auto quoted = [&] {
    std::string out(1, '\'');
    out += one_line(line != nullptr ? *line : json.dump(), 120);
    out += '\'';
    return out;
  };
  PluginReply reply;
  if (kind == RequestKind::policy && interface != nullptr &&
      policy_wire::reads_outputs(*interface)) {
    reply.outputs = policy_wire::read_outputs(json, *interface, answered);
    if (!interface->named()) reply.chunk = reply.outputs.front().poses;
    return reply;
  }
  if (kind == RequestKind::decode || kind == RequestKind::policy) {
    if (json.contains("chunk")) reply.chunk = read_chunk(json["chunk"], answered);
    if (reply.chunk.empty()) {
      throw PluginError(
          answered + (kind == RequestKind::decode ? ", a decode request," : ", a policy request,") +
          " without a \"chunk\" of poses: " + quoted());
    }
    return reply;
  }
  if (!json.contains("actions")) throw PluginError(answered + " without \"actions\": " + quoted());
  reply.actions = read_numbers(json["actions"], "actions", answered);
  if (reply.actions.size() == 0) throw PluginError(answered + " with no actions");
  reply.has_observation = json.contains("observation") && !json["observation"].is_null();
  if (reply.has_observation)
    reply.observation = read_numbers(json["observation"], "observation", answered);
  if (kind == RequestKind::flow) {
    if (!json.contains("flow_input") || !json.contains("flow_target")) {
      throw PluginError(answered +
                        ", a flow request (it carries eps and t), without \"flow_input\" and "
                        "\"flow_target\"; answer them, or do not declare \"flow\" in the hello");
    }
    reply.flow_input = read_numbers(json["flow_input"], "flow_input", answered);
    reply.flow_target = read_numbers(json["flow_target"], "flow_target", answered);
    reply.has_flow = true;
  }
  return reply;
}

// The hello's "cameras": what the policy sees, each field checked with the fix in the message.
CameraRig read_cameras(const nlohmann::json& cameras, const std::string& answered) {
  const std::string form =
      "; declare {\"views\": [\"eye_in_hand\"], \"image_size\": [64, 48], \"channels\": "
      "\"rgbd\", \"floor\": false} (only views is needed)";
  if (!cameras.is_object() || !cameras.contains("views") || !cameras["views"].is_array())
    throw PluginError(answered + " with a hello whose \"cameras\" is " +
                      one_line(cameras.dump(), 60) + form);
  CameraRig rig;
  rig.views.clear();
  try {
    for (const nlohmann::json& view : cameras["views"]) {
      if (!view.is_string()) throw InvalidArgument("a camera's name must be a string");
      rig.views.push_back(parse_camera_view(view.get<std::string>()));
    }
    if (cameras.contains("image_size")) {
      const nlohmann::json& size = cameras["image_size"];
      if (!size.is_array() || size.size() != 2 || !size[0].is_number_integer() ||
          !size[1].is_number_integer() || size[0].get<long long>() < 1 ||
          size[1].get<long long>() < 1 || size[0].get<long long>() > 1024 ||
          size[1].get<long long>() > 1024) {
        throw InvalidArgument("\"image_size\" " + one_line(size.dump(), 40) +
                              " is not [width, height], each 1 to 1024");
      }
      rig.camera.width = size[0].get<int>();
      rig.camera.height = size[1].get<int>();
    }
    if (cameras.contains("channels")) {
      if (!cameras["channels"].is_string())
        throw InvalidArgument("\"channels\" must be \"depth\", \"rgb\" or \"rgbd\"");
      rig.channels = parse_image_channels(cameras["channels"].get<std::string>());
    }
    if (cameras.contains("floor")) {
      if (!cameras["floor"].is_boolean()) throw InvalidArgument("\"floor\" must be true or false");
      rig.floor = cameras["floor"].get<bool>();
    }
    rig.validate();
  } catch (const InvalidArgument& e) {
    throw PluginError(answered + " with a hello whose \"cameras\" is wrong: " + e.what() + form);
  }
  return rig;
}

}  // namespace

PluginReply parse_reply(const std::string& line, int id, RequestKind kind, const std::string& who,
                        bool hello_allowed, const PolicyInterface* interface) {
  const nlohmann::json json = parse_line(line, id, who);
  PluginReply reply;
  if (json.contains("hello")) {
    const nlohmann::json& hello = json["hello"];
    if (!hello_allowed)
      throw PluginError(reply_to(who, id) +
                        " with a hello; a hello may only answer the first request");
    if (!hello.is_object())
      throw PluginError(reply_to(who, id) + " with a hello that is not an object");
    PluginCapabilities capabilities;
    // Compared as the integer JSON holds: converted to int first, 2^32 + 2 would pass for 2.
    const long long protocol = hello.contains("protocol") && hello["protocol"].is_number_integer()
                                   ? hello["protocol"].get<long long>()
                                   : 2;
    if (protocol < 2 || protocol > kProtocolVersion) {
      throw PluginError(reply_to(who, id) + " with a hello for protocol " +
                        one_line(hello["protocol"].dump(), 40) +
                        "; this audit speaks protocols 1 and " + std::to_string(kProtocolVersion));
    }
    capabilities.protocol = static_cast<int>(protocol);
    capabilities.extra_pose_names = read_names(hello, "extra_poses", id, who);
    capabilities.scalar_names = read_names(hello, "scalars", id, who);
    capabilities.decode = read_flag(hello, "decode", id, who);
    capabilities.flow = read_flag(hello, "flow", id, who);
    if (hello.contains("noise") && !hello["noise"].is_null()) {
      if (!hello["noise"].is_number_integer() || hello["noise"].get<long long>() < 1 ||
          hello["noise"].get<long long>() > kMaxPolicyNoise) {
        throw PluginError(reply_to(who, id) + " with a hello whose \"noise\" is " +
                          one_line(hello["noise"].dump(), 40) + ", not a length between 1 and " +
                          std::to_string(kMaxPolicyNoise));
      }
      capabilities.noise = hello["noise"].get<int>();
    }
    if (hello.contains("batch") && !hello["batch"].is_null()) {
      if (!hello["batch"].is_number_integer() || hello["batch"].get<long long>() < 1 ||
          hello["batch"].get<long long>() > kMaxBatchSize) {
        throw PluginError(reply_to(who, id) + " with a hello whose \"batch\" is " +
                          one_line(hello["batch"].dump(), 40) +
                          ", not a number of scenes per request between 1 and " +
                          std::to_string(kMaxBatchSize) + " (256 suits most plug-ins)");
      }
      capabilities.batch = hello["batch"].get<int>();
    }
    // The encodings the plug-in reads and writes besides JSON numbers: the audit takes base64
    // when it is offered and ignores names it does not know (a newer plug-in may offer more).
    for (const std::string& name : read_names(hello, "encodings", id, who)) {
      if (name == "base64") capabilities.encoding = NumberEncoding::base64;
    }
    if (hello.contains("cameras") && !hello["cameras"].is_null())
      capabilities.cameras = read_cameras(hello["cameras"], reply_to(who, id));
    capabilities.policy = policy_wire::read_interface(hello, reply_to(who, id));
    if (hello.contains("outputs") && hello["outputs"].is_object()) {
      // nlohmann::json sorts an object's keys; the hello's order says which pose output the
      // closed loop executes (the first), so read it again in its own order.
      // Parsed into a variable first: a range-for over a temporary's member would dangle.
      const nlohmann::ordered_json ordered = nlohmann::ordered_json::parse(line);
      std::vector<std::string> order;
      for (const auto& item : ordered["hello"]["outputs"].items()) order.push_back(item.key());
      policy_wire::order_outputs(capabilities.policy, order);
    }
    reply.hello = capabilities;
    return reply;
  }
  return read_answer(json, kind, reply_to(who, id), &line, interface);
}

std::vector<PluginReply> parse_batch_reply(const std::string& line, int id, RequestKind kind,
                                           const std::string& who, std::size_t count,
                                           const PolicyInterface* interface) {
  const nlohmann::json json = parse_line(line, id, who);
  const std::string answered = who + " answered batched request " + std::to_string(id);
  const std::string form = "; answer {\"id\": " + std::to_string(id) +
                           ", \"batch\": [answer, ...]} with one answer per scene of the "
                           "request's \"batch\", in its order";
  if (!json.contains("batch") || !json["batch"].is_array()) {
    throw PluginError(answered + " (" + std::to_string(count) +
                      " scenes) without a \"batch\" list" + form +
                      " (its hello declared \"batch\"): '" + one_line(line, 120) + "'");
  }
  const nlohmann::json& items = json["batch"];
  if (items.size() != count) {
    throw PluginError(answered + " with " + std::to_string(items.size()) + " answers for " +
                      std::to_string(count) + " scenes" + form);
  }
  std::vector<PluginReply> replies;
  replies.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const std::string item =
        answered + " (item " + std::to_string(i) + " of " + std::to_string(count) + ")";
    if (!items[i].is_object()) {
      throw PluginError(item + " with " + one_line(items[i].dump(), 40) +
                        ", not an object; each item is what the single request's answer would "
                        "be, without the id, e.g. {\"actions\": [...]}");
    }
    replies.push_back(read_answer(items[i], kind, item, nullptr, interface));
  }
  return replies;
}

}  // namespace handcentric::props
