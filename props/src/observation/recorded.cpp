#include "handcentric/props/observation/recorded.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "../wire_arrays.hpp"
#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/props/observation/hands.hpp"
#include "npz.hpp"

namespace handcentric::props {
namespace {

using Part = RecordedPart;

constexpr const char* kParts =
    "history, chunk, hand_points, world_points, extra_poses, scalars, held, episode";

// Nested JSON lists of numbers into a rectangular array (a ragged list is an error).
void flatten(const nlohmann::json& v, std::size_t depth, int& leaf_depth, Part& out,
             const std::string& where) {
  if (v.is_number()) {
    if (leaf_depth < 0) leaf_depth = static_cast<int>(depth);
    if (leaf_depth != static_cast<int>(depth)) throw InvalidArgument(where + " is a ragged list");
    out.values.push_back(v.get<double>());
    return;
  }
  if (!v.is_array())
    throw InvalidArgument(where + " holds " + std::string(v.type_name()) +
                          "; give numbers (nested lists) or an encoded array");
  if (leaf_depth >= 0 && leaf_depth <= static_cast<int>(depth))
    throw InvalidArgument(where + " is a ragged list");
  const auto size = static_cast<std::int64_t>(v.size());
  if (out.shape.size() == depth) {
    out.shape.push_back(size);
  } else if (out.shape[depth] != size) {
    throw InvalidArgument(where + " is a ragged list");
  }
  for (const auto& item : v) flatten(item, depth + 1, leaf_depth, out, where);
}

Part part_of_json(const nlohmann::json& v, const std::string& where) {
  Part out;
  if (wire::is_encoded(v)) {
    wire::Array a;
    try {
      a = wire::read_array(v, where);
    } catch (const Error& e) {
      throw InvalidArgument(e.what());
    }
    for (const std::size_t size : a.shape) out.shape.push_back(static_cast<std::int64_t>(size));
    out.values = std::move(a.values);
    out.float32 = a.dtype == wire::Dtype::float32;
    return out;
  }
  int leaf_depth = -1;
  flatten(v, 0, leaf_depth, out, where);
  return out;
}

std::string shape_text(const std::vector<std::int64_t>& shape) {
  std::string out = "(";
  for (std::size_t i = 0; i < shape.size(); ++i) out += (i ? ", " : "") + std::to_string(shape[i]);
  return out + (shape.size() == 1 ? ",)" : ")");
}

void require_finite(const Part& p, const std::string& where) {
  for (std::size_t i = 0; i < p.values.size(); ++i) {
    if (!std::isfinite(p.values[i]))
      throw InvalidArgument(where + " has a non-finite number at flat index " + std::to_string(i));
  }
}

// A recorded pose: the last row (0, 0, 0, 1) to 1e-6 and a rotation block orthonormal to 1e-5
// (a float32 dataset's are to ~1e-7), projected onto the nearest rotation so that g T is a rigid
// transform; anything further from one is an error, not silently repaired.
RigidTransform pose_of(const double* m, const std::string& where) {
  Eigen::Matrix4d M;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) M(r, c) = m[4 * r + c];
  const double row =
      (M.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff<Eigen::PropagateNaN>();
  if (!(row <= 1e-6))
    throw InvalidArgument(where + " is not a rigid transform: its last row is " +
                          format_matrix(Eigen::MatrixXd(M.row(3))) + ", expected 0 0 0 1");
  const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
  const double error = (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
  if (!(error <= 1e-5) || !(R.determinant() > 0))
    throw InvalidArgument(where +
                          " is not a rigid transform: |R^T R - I| = " + format_number(error) +
                          " (at most 1e-5), det R = " + format_number(R.determinant()) +
                          "; store world_T_hand matrices");
  return RigidTransform(Rotation::nearest(R), M.topRightCorner<3, 1>());
}

std::vector<RigidTransform> poses_of(const Part& p, const std::string& where, bool at_least_one) {
  if (p.shape.size() != 3 || p.shape[1] != 4 || p.shape[2] != 4 || (at_least_one && p.shape[0] < 1))
    throw InvalidArgument(where + " has shape " + shape_text(p.shape) + "; expected (n, 4, 4)" +
                          (at_least_one ? " with n >= 1" : ""));
  std::vector<RigidTransform> out;
  for (std::int64_t i = 0; i < p.shape[0]; ++i)
    out.push_back(pose_of(p.values.data() + 16 * i, where + "[" + std::to_string(i) + "]"));
  return out;
}

std::vector<Eigen::Vector3d> points_of(const Part& p, const std::string& where) {
  if (p.values.empty() && !p.shape.empty() && p.shape[0] == 0) return {};
  if (p.shape.size() != 2 || p.shape[1] != 3)
    throw InvalidArgument(where + " has shape " + shape_text(p.shape) + "; expected (n, 3)");
  std::vector<Eigen::Vector3d> out;
  for (std::int64_t i = 0; i < p.shape[0]; ++i)
    out.emplace_back(p.values[3 * i], p.values[3 * i + 1], p.values[3 * i + 2]);
  return out;
}

}  // namespace

Scene recorded_observation(const std::map<std::string, RecordedPart>& parts,
                           const std::string& where) {
  Scene s;
  bool has_history = false;
  std::vector<std::pair<std::string, std::vector<RigidTransform>>> hands;  // history/NAME
  for (const auto& [key, part] : parts) {
    const std::string at = where + " '" + key + "'";
    require_finite(part, at);
    const std::size_t slash = key.find('/');
    const std::string kind = key.substr(0, slash);
    const std::string name = slash == std::string::npos ? "" : key.substr(slash + 1);
    if (slash != std::string::npos && name.empty())
      throw InvalidArgument(at + " has an empty name");
    if (key == "history") {
      s.world_T_hand_history = poses_of(part, at, true);
      has_history = true;
    } else if (kind == "history" && !name.empty()) {
      hands.emplace_back(name, poses_of(part, at, true));
    } else if (key == "chunk") {
      s.world_T_hand_chunk = poses_of(part, at, true);
    } else if (key == "hand_points") {
      s.hand_points = points_of(part, at);
    } else if (key == "world_points") {
      s.world_points = points_of(part, at);
    } else if (kind == "extra_poses" && !name.empty()) {
      if (part.shape != std::vector<std::int64_t>{4, 4})
        throw InvalidArgument(at + " has shape " + shape_text(part.shape) + "; expected (4, 4)");
      if (is_hand_pose(name))
        throw InvalidArgument(at + ": the names \"" + kHandPosePrefix +
                              "...\" are the hands'; record a hand's poses under history as "
                              "{hand: (H+1, 4, 4)}");
      s.extra_poses.emplace_back(name, pose_of(part.values.data(), at));
    } else if (kind == "scalars" && !name.empty()) {
      if (part.values.size() != 1 || part.shape.size() > 1)
        throw InvalidArgument(at + " has shape " + shape_text(part.shape) +
                              "; a scalar is one number (an array belongs under 'held')");
      s.scalars.emplace_back(name, part.values.front());
    } else if (kind == "held" && !name.empty()) {
      auto array = std::make_shared<HeldArray>();
      array->shape = part.shape;
      array->values = part.values;
      array->float32 = part.float32;
      s.held.emplace_back(name, std::move(array));
    } else {
      throw InvalidArgument(where + " has a part '" + key + "'; the parts are " + kParts +
                            " (extra_poses, scalars and held by name)");
    }
  }
  if (hands.size() == 1)
    throw InvalidArgument(where + " has one history per hand for one hand, '" +
                          hands.front().first +
                          "': with one hand give 'history' as an array (H+1, 4, 4)");
  if (has_history && !hands.empty())
    throw InvalidArgument(where + " has both 'history' and 'history/" + hands.front().first +
                          "': record one history, or one per hand {hand: (H+1, 4, 4)}");
  // One history per hand: every hand as its extra poses (observation/hands.hpp), the first in
  // sorted order the scene's own until recorded_with_hands() picks the audit's first hand.
  for (const auto& [hand, history] : hands) {
    for (std::size_t k = 0; k < history.size(); ++k)
      s.extra_poses.emplace_back(hand_pose_name(hand, static_cast<int>(k)), history[k]);
  }
  if (!hands.empty()) {
    s.world_T_hand_history = hands.front().second;
    has_history = true;
  }
  if (!has_history)
    throw InvalidArgument(where +
                          " has no 'history' (H+1, 4, 4) of world_T_hand poses; every "
                          "observation needs at least the hand now");
  return s;
}

std::optional<std::int64_t> episode_of(std::map<std::string, RecordedPart>& parts,
                                       const std::string& where) {
  const auto found = parts.find("episode");
  if (found == parts.end()) return std::nullopt;
  const Part part = std::move(found->second);
  parts.erase(found);
  const double value = part.values.size() == 1 ? part.values.front() : 0.5;
  if (part.values.size() != 1 || part.shape.size() > 1)
    throw InvalidArgument(where + " 'episode' has shape " + shape_text(part.shape) +
                          "; an episode index is one integer per observation");
  if (!(std::abs(value) < 9e15) || std::round(value) != value)
    throw InvalidArgument(where + " 'episode' is " + format_number(value) +
                          "; an episode index is an integer: give each observation's episode "
                          "as 0, 1, 2, ...");
  return static_cast<std::int64_t>(value);
}

namespace {

// JSON objects under extra_poses, scalars and held become parts "extra_poses/NAME", ...
std::map<std::string, Part> parts_of_line(const nlohmann::json& line, const std::string& where) {
  if (!line.is_object())
    throw InvalidArgument(where + " is " + std::string(line.type_name()) +
                          ", not an object with the parts " + kParts);
  std::map<std::string, Part> parts;
  for (const auto& [key, value] : line.items()) {
    // {hand: history}: an object that is not an encoded array (those carry "data").
    const bool per_hand = key == "history" && value.is_object() && !value.contains("data");
    if (key == "extra_poses" || key == "scalars" || key == "held" || per_hand) {
      if (!value.is_object())
        throw InvalidArgument(where + " '" + key + "' must be an object {name: value}");
      for (const auto& [name, item] : value.items())
        parts[key + "/" + name] = part_of_json(item, where + " '" + key + "/" + name + "'");
    } else {
      parts[key] = part_of_json(value, where + " '" + key + "'");
    }
  }
  return parts;
}

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

/// An .npz's observations: the arrays split along their first axis, N counted by "history" (or
/// the first "history/NAME" of several hands').
RecordedObservations from_npz(const std::map<std::string, npz::Array>& arrays,
                              const std::string& path) {
  auto history = arrays.find("history");
  if (history == arrays.end()) {
    history = arrays.lower_bound("history/");
    if (history != arrays.end() && history->first.rfind("history/", 0) != 0) history = arrays.end();
  }
  if (history == arrays.end() || history->second.shape.empty())
    throw InvalidArgument("observations file '" + path +
                          "' has no array 'history' of shape (N, H+1, 4, 4)");
  const std::string& counted = history->first;
  const std::int64_t n = history->second.shape[0];
  // Each observation has at least one pose of 16 numbers: bounds N before one map per
  // observation is made (a shape such as (10**12, 0, 4, 4) holds no numbers at all).
  if (history->second.values.size() / 16 < static_cast<std::uint64_t>(n))
    throw InvalidArgument("observations file '" + path + "': array '" + counted + "' has shape " +
                          shape_text(history->second.shape) +
                          "; expected (N, H+1, 4, 4) with H+1 >= 1");
  std::vector<std::map<std::string, Part>> per(static_cast<std::size_t>(n));
  for (const auto& [name, a] : arrays) {
    if (a.shape.empty() || a.shape[0] != n)
      throw InvalidArgument("observations file '" + path + "': array '" + name + "' has shape " +
                            shape_text(a.shape) + "; every array's first axis counts the " +
                            std::to_string(n) + " observations of '" + counted + "'");
    const std::vector<std::int64_t> item_shape(a.shape.begin() + 1, a.shape.end());
    const std::size_t item = n == 0 ? 0 : a.values.size() / static_cast<std::size_t>(n);
    for (std::int64_t i = 0; i < n; ++i) {
      Part p;
      p.shape = item_shape;
      p.float32 = a.float32;
      p.values.assign(a.values.begin() + static_cast<std::ptrdiff_t>(item * i),
                      a.values.begin() + static_cast<std::ptrdiff_t>(item * (i + 1)));
      per[static_cast<std::size_t>(i)][name] = std::move(p);
    }
  }
  std::vector<Scene> out;
  std::vector<std::optional<std::int64_t>> episode;
  for (std::int64_t i = 0; i < n; ++i) {
    const std::string where = path + " observation " + std::to_string(i);
    episode.push_back(episode_of(per[static_cast<std::size_t>(i)], where));
    out.push_back(recorded_observation(per[static_cast<std::size_t>(i)], where));
  }
  return recorded_observations(std::move(out), path, episode);
}

template <class Pairs>
std::string names_of(const Pairs& pairs) {
  std::string out;
  for (const auto& [name, value] : pairs) out += (out.empty() ? "" : ", ") + name;
  return "[" + out + "]";
}

}  // namespace

void RecordedObservations::validate() const {
  if (scenes.empty())
    throw InvalidArgument("the observations of " + source +
                          " are empty: give at least one (docs/AUDIT.md, \"Your own "
                          "observations\")");
  const Scene& first = scenes.front();
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    const Scene& s = scenes[i];
    const std::string where = source + " observation " + std::to_string(i);
    try {
      s.validate();
    } catch (const Error& e) {
      throw InvalidArgument(where + ": " + e.what());
    }
    if (names_of(s.extra_poses) != names_of(first.extra_poses) ||
        names_of(s.scalars) != names_of(first.scalars) ||
        names_of(s.held) != names_of(first.held)) {
      throw InvalidArgument(where + " names extra_poses " + names_of(s.extra_poses) + ", scalars " +
                            names_of(s.scalars) + ", held " + names_of(s.held) +
                            " but observation 0 names " + names_of(first.extra_poses) + ", " +
                            names_of(first.scalars) + ", " + names_of(first.held) +
                            ": every observation carries the same parts");
    }
    for (const auto& [name, array] : s.held) array->validate(name);
  }
  if (!episode.empty() && episode.size() != scenes.size())
    throw InvalidArgument("the observations of " + source + " have " +
                          std::to_string(scenes.size()) + " observations but " +
                          std::to_string(episode.size()) + " episode indices: give one each");
  // An episode's observations together: an index that comes back after another's is an error.
  std::map<std::int64_t, std::size_t> ended;  // episode -> its last observation
  for (const RecordedEpisode& e : episodes()) {
    const auto seen = ended.find(e.index);
    if (seen != ended.end()) {
      throw InvalidArgument(source + " observation " + std::to_string(e.first) + " is of episode " +
                            std::to_string(e.index) + ", which ended at observation " +
                            std::to_string(seen->second) +
                            ": keep each episode's observations together, in their order");
    }
    ended[e.index] = e.first + e.steps - 1;
  }
}

std::vector<RecordedEpisode> RecordedObservations::episodes() const {
  std::vector<RecordedEpisode> out;
  for (std::size_t i = 0; i < episode.size(); ++i) {
    if (out.empty() || out.back().index != episode[i]) out.push_back({episode[i], i, 0});
    ++out.back().steps;
  }
  return out;
}

std::vector<std::string> RecordedObservations::hands() const {
  std::vector<std::string> out;
  if (scenes.empty()) return out;
  for (const auto& [name, pose] : scenes.front().extra_poses) {
    if (is_hand_pose(name) && name.find("@-") == std::string::npos)
      out.push_back(name.substr(std::string(kHandPosePrefix).size()));
  }
  std::sort(out.begin(), out.end());
  return out;
}

bool RecordedObservations::has_world_points() const {
  for (const Scene& s : scenes)
    if (!s.world_points.empty()) return true;
  return false;
}

std::string RecordedObservations::verdict_note() const {
  return "cases drawn from " + std::to_string(scenes.size()) + " recorded observations (" + source +
         "), each with a random g";
}

void RecordedObservations::require_inside(const Workspace& box) const {
  for (std::size_t i = 0; i < scenes.size(); ++i) {
    if (!box.contains(scenes[i]))
      throw InvalidArgument("observation " + std::to_string(i) + " of " + source +
                            " lies outside the workspace " + box.describe() +
                            ": give a workspace that holds the data");
  }
}

RecordedObservations recorded_observations(
    std::vector<Scene> scenes, std::string source,
    const std::vector<std::optional<std::int64_t>>& episode) {
  RecordedObservations out;
  out.source = std::move(source);
  const auto without = std::find(episode.begin(), episode.end(), std::nullopt);
  if (without != episode.end() &&
      std::any_of(episode.begin(), episode.end(), [](const auto& e) { return e.has_value(); })) {
    throw InvalidArgument(out.source + " observation " + std::to_string(without - episode.begin()) +
                          " has no 'episode' while others have one: give every observation its "
                          "episode, or none");
  }
  for (const std::optional<std::int64_t>& e : episode)
    if (e) out.episode.push_back(*e);
  out.has_chunks = !scenes.empty();
  for (Scene& s : scenes) {
    out.has_chunks = out.has_chunks && !s.world_T_hand_chunk.empty();
    if (s.world_T_hand_chunk.empty() && !s.world_T_hand_history.empty())
      s.world_T_hand_chunk.push_back(s.world_T_hand0());
  }
  out.scenes = std::move(scenes);
  out.validate();
  return out;
}

RecordedObservations observations_from_json_lines(std::istream& in, const std::string& source) {
  std::vector<Scene> scenes;
  std::vector<std::optional<std::int64_t>> episode;
  std::string line;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::string where = source + " line " + std::to_string(number);
    nlohmann::json parsed;
    try {
      parsed = nlohmann::json::parse(line);
    } catch (const nlohmann::json::exception& e) {
      throw InvalidArgument(where + " is not JSON (" + e.what() +
                            "): write one observation object per line");
    }
    std::map<std::string, Part> parts = parts_of_line(parsed, where);
    episode.push_back(episode_of(parts, where));
    scenes.push_back(recorded_observation(parts, where));
  }
  if (in.bad()) throw FileError("cannot read the observations of " + source);
  return recorded_observations(std::move(scenes), source, episode);
}

RecordedObservations observations_from_npz(std::string_view bytes, const std::string& source) {
  return from_npz(npz::read_bytes(bytes, source, kMaxRecordedBytes), source);
}

RecordedObservations read_observations(const std::string& path) {
  if (ends_with(path, ".npz")) return from_npz(npz::read(path, kMaxRecordedBytes), path);
  if (!ends_with(path, ".jsonl") && !ends_with(path, ".json-lines") && !ends_with(path, ".ndjson"))
    throw InvalidArgument("observations file '" + path +
                          "' is neither .jsonl nor .npz: name it by its format");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError("cannot open observations file '" + path + "': check the path");
  in.seekg(0, std::ios::end);
  if (static_cast<std::uint64_t>(in.tellg()) > kMaxRecordedBytes)
    throw FileError("observations file '" + path + "' is above the limit of " +
                    std::to_string(kMaxRecordedBytes) + " bytes");
  in.seekg(0);
  return observations_from_json_lines(in, path);
}

}  // namespace handcentric::props
