// The demo file format shared by the tasks (demo_file.hpp, docs/SIM.md).
#include "demo_file.hpp"

#include <cmath>
#include <cstdint>
#include <fstream>
#include <istream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "handcentric/core/format.hpp"
#include "handcentric/core/atomic_file.hpp"

namespace handcentric::sim::detail {
namespace {

using nlohmann::json;

constexpr const char* kFormat = "handcentric-demos";
constexpr int kVersion = 1;
/// Off-plane entries (z, roll, pitch) above this make a pose non-planar.
constexpr double kPlanarTolerance = 1e-9;

bool is_planar(const RigidTransform& pose) {
  const Eigen::Matrix4d M = pose.matrix();
  return std::abs(M(2, 3)) <= kPlanarTolerance && std::abs(M(0, 2)) <= kPlanarTolerance &&
         std::abs(M(1, 2)) <= kPlanarTolerance && std::abs(M(2, 0)) <= kPlanarTolerance &&
         std::abs(M(2, 1)) <= kPlanarTolerance && std::abs(M(2, 2) - 1.0) <= kPlanarTolerance;
}

json pose_to_json(const RigidTransform& pose) {
  const Eigen::Matrix4d M = pose.matrix();
  json rows = json::array();
  for (int r = 0; r < 3; ++r) rows.push_back({M(r, 0), M(r, 1), M(r, 2), M(r, 3)});
  return rows;
}

[[noreturn]] void fail(const std::string& path, const std::string& where, const std::string& what) {
  throw InvalidDemoFile("demo file '" + path + "', " + where + ": " + what);
}

RigidTransform pose_from_json(const json& value, const std::string& path, const std::string& where,
                              bool planar) {
  if (!value.is_array() || value.size() != 3) {
    fail(path, where,
         "a pose must be a 3x4 matrix [[r00, r01, r02, x], [..], [..]], got " + value.dump());
  }
  Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
  for (int r = 0; r < 3; ++r) {
    const json& row = value[static_cast<std::size_t>(r)];
    if (!row.is_array() || row.size() != 4) {
      fail(path, where,
           "row " + std::to_string(r) + " of a pose must hold 4 numbers, got " + row.dump());
    }
    for (int c = 0; c < 4; ++c) {
      const json& entry = row[static_cast<std::size_t>(c)];
      // JSON has no NaN: nlohmann writes NaN and infinity as null
      if (!entry.is_number()) {
        fail(path, where,
             "entry (" + std::to_string(r) + ", " + std::to_string(c) +
                 ") is not a finite number: " + entry.dump());
      }
      M(r, c) = entry.get<double>();
    }
  }
  RigidTransform pose;
  try {
    pose = RigidTransform::from_matrix(M);
  } catch (const Error& e) {
    fail(path, where, std::string("not a rigid transform: ") + e.what());
  }
  if (planar && !is_planar(pose)) {
    fail(path, where,
         "not a planar pose (rotation about z, z = 0): " + format_matrix(M.topRows<3>()) +
             "; the 2D task uses RigidTransform::planar(theta, x, y)");
  }
  return pose;
}

void check_demo(const DemoFileTask& task, const DemoRecord& demo, std::size_t index) {
  const std::string where = "demo " + std::to_string(index + 1);
  if (demo.world_T_hand.empty())
    throw InvalidArgument(where + " has no hand pose; a demo needs at least one");
  if (!task.planar) return;
  if (!is_planar(demo.world_T_object))
    throw InvalidArgument(where + ": " + task.object_key + " is not planar");
  for (std::size_t t = 0; t < demo.world_T_hand.size(); ++t) {
    if (!is_planar(demo.world_T_hand[t])) {
      throw InvalidArgument(where + ": world_T_hand[" + std::to_string(t) + "] is not planar");
    }
  }
}

// One line of `in` into `line`, without its newline; `newline` says whether it ended in one.
// False at the end of the file with nothing read. Stops with InvalidDemoFile once the line passes
// limits.max_line_bytes, having read (and kept) no more than that.
bool read_line(std::istream& in, std::string& line, bool& newline, const DemoFileLimits& limits,
               const std::string& path, const std::string& where) {
  line.clear();
  newline = false;
  std::streambuf& buffer = *in.rdbuf();
  for (;;) {
    const int c = buffer.sbumpc();
    if (c == std::char_traits<char>::eof()) return !line.empty();
    if (c == '\n') {
      newline = true;
      return true;
    }
    if (line.size() == limits.max_line_bytes) {
      fail(path, where,
           "the line is longer than " + std::to_string(limits.max_line_bytes) +
               " bytes, the limit for one demo: this is not a demo file of this task, or it is "
               "damaged");
    }
    line.push_back(static_cast<char>(c));
  }
}

// json::parse with a bound on nesting, checked as each container opens (nlohmann's parser keeps
// its own stack, so this is about memory and the size of the tree, not the call stack).
json parse_line(const std::string& line, const DemoFileLimits& limits, const std::string& path,
                const std::string& where) {
  const json::parser_callback_t depth_guard = [&](int depth, json::parse_event_t event, json&) {
    // `depth` counts the containers around the one that opens
    if ((event == json::parse_event_t::object_start || event == json::parse_event_t::array_start) &&
        depth >= limits.max_json_depth) {
      fail(path, where,
           "JSON nested deeper than " + std::to_string(limits.max_json_depth) +
               " levels (a demo record has 4): this is not a demo file of this task");
    }
    return true;
  };
  return json::parse(line, depth_guard);
}

}  // namespace

void save_demo_records(const std::string& path, const DemoFileTask& task, double clearance,
                       const std::vector<DemoRecord>& demos) {
  std::ostringstream out;
  json header = {{"format", kFormat},
                 {"version", kVersion},
                 {"task", task.name},
                 {"count", demos.size()},
                 {task.clearance_key, clearance}};
  out << header.dump() << "\n";
  for (std::size_t i = 0; i < demos.size(); ++i) {
    check_demo(task, demos[i], i);
    json record;
    record[task.object_key] = pose_to_json(demos[i].world_T_object);
    json hands = json::array();
    for (const RigidTransform& pose : demos[i].world_T_hand) hands.push_back(pose_to_json(pose));
    record["world_T_hand"] = std::move(hands);
    out << record.dump() << "\n";
  }
  write_file_atomically(path, out.str());
}

namespace {

// The header line, its format and version checked; `path` names the source in errors.
json read_header(std::istream& in, const std::string& path, const DemoFileLimits& limits) {
  std::string line;
  bool newline = false;
  if (!read_line(in, line, newline, limits, path, "line 1 (header)")) {
    fail(path, "line 1", "the file is empty; expected a header line");
  }
  json header;
  try {
    header = parse_line(line, limits, path, "line 1 (header)");
  } catch (const json::exception&) {
    fail(path, "line 1 (header)", "not valid JSON");
  }
  // Types first: json::value("format", "") throws a json::type_error on a non-string format.
  if (!header.is_object() || !header.contains("format") || header["format"] != kFormat) {
    fail(path, "line 1 (header)", std::string("expected {\"format\": \"") + kFormat + "\", ...}");
  }
  if (!header.contains("version") || !header["version"].is_number_integer() ||
      header["version"] != kVersion) {
    fail(path, "line 1 (header)",
         "unsupported version " +
             (header.contains("version") ? header["version"].dump() : "(none)") +
             "; this build reads version " + std::to_string(kVersion));
  }
  return header;
}

// A header without a task is the 2D task's: files written before the 3D task existed.
std::string task_of(const json& header) {
  return !header.contains("task")     ? "peg2d"
         : header["task"].is_string() ? header["task"].get<std::string>()
                                      : header["task"].dump();
}

// The one reader of demo files, from a file or from memory; `path` names the source in errors.
std::vector<DemoRecord> read_demo_records(std::istream& in, const std::string& path,
                                          const DemoFileTask& task, const DemoFileLimits& limits) {
  json header = read_header(in, path, limits);
  std::string line;
  bool newline = false;
  const std::string file_task = task_of(header);
  if (file_task != task.name) {
    fail(path, "line 1 (header)",
         "a demo file of task '" + file_task + "', not '" + task.name + "': use a " + task.name +
             " demo file here (" + file_task + " files go with --task " + file_task + ")");
  }
  if (!header.contains("count") || !header["count"].is_number_unsigned()) {
    fail(path, "line 1 (header)", "\"count\" must be a non-negative integer");
  }
  const auto count = header["count"].get<std::uint64_t>();
  if (count > limits.max_demos) {
    fail(path, "line 1 (header)",
         "the header announces " + std::to_string(count) + " demos, more than the limit of " +
             std::to_string(limits.max_demos) + ": split the data set, or fix the count");
  }
  std::vector<DemoRecord> demos;
  std::size_t poses = 0;
  for (std::size_t record = 1; record <= count; ++record) {
    const std::string where =
        "record " + std::to_string(record) + " (line " + std::to_string(record + 1) + ")";
    if (!read_line(in, line, newline, limits, path, where)) {
      fail(path, where,
           "missing: the header promises " + std::to_string(count) +
               " demos but the file ends after " + std::to_string(record - 1) +
               " (truncated file?)");
    }
    if (!newline) fail(path, where, "the line has no final newline (truncated file?)");
    json value;
    try {
      value = parse_line(line, limits, path, where);
    } catch (const json::exception&) {
      fail(path, where, "not valid JSON (truncated or corrupted line)");
    }
    if (!value.is_object() || !value.contains(task.object_key) || !value.contains("world_T_hand")) {
      fail(path, where,
           "expected {\"" + task.object_key + "\": pose, \"world_T_hand\": [pose, ...]}");
    }
    DemoRecord demo;
    demo.world_T_object =
        pose_from_json(value[task.object_key], path, where + ", " + task.object_key, task.planar);
    const json& hands = value["world_T_hand"];
    if (!hands.is_array() || hands.empty())
      fail(path, where, "world_T_hand must be a non-empty array of poses");
    if (hands.size() > limits.max_poses_per_demo) {
      fail(path, where,
           "a demo of " + std::to_string(hands.size()) + " poses, more than the limit of " +
               std::to_string(limits.max_poses_per_demo) + " for one demo");
    }
    poses += hands.size();
    if (poses > limits.max_poses) {
      fail(path, where,
           "the demos so far hold " + std::to_string(poses) + " poses, more than the limit of " +
               std::to_string(limits.max_poses) + " for one file: split the data set");
    }
    demo.world_T_hand.reserve(hands.size());
    for (std::size_t t = 0; t < hands.size(); ++t) {
      demo.world_T_hand.push_back(pose_from_json(
          hands[t], path, where + ", world_T_hand[" + std::to_string(t) + "]", task.planar));
    }
    demos.push_back(std::move(demo));
  }
  if (read_line(in, line, newline, limits, path, "line " + std::to_string(count + 2)) &&
      !line.empty()) {
    fail(path, "line " + std::to_string(count + 2),
         "extra data after the " + std::to_string(count) + " demos the header promises");
  }
  return demos;
}

}  // namespace

namespace {
std::ifstream open_demo_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InvalidDemoFile("cannot open demo file '" + path +
                          "'; check the path (make one with `handcentric demos`)");
  return in;
}
}  // namespace

std::vector<DemoRecord> load_demo_records(const std::string& path, const DemoFileTask& task,
                                          const DemoFileLimits& limits) {
  std::ifstream in = open_demo_file(path);
  return read_demo_records(in, path, task, limits);
}

}  // namespace handcentric::sim::detail

namespace handcentric::sim {

std::string demo_file_task(const std::string& path, const DemoFileLimits& limits) {
  std::ifstream in = detail::open_demo_file(path);
  return detail::task_of(detail::read_header(in, path, limits));
}

PegHoleGeometry demo_file_geometry(const std::string& path, const DemoFileLimits& limits) {
  std::ifstream in = detail::open_demo_file(path);
  const nlohmann::json header = detail::read_header(in, path, limits);
  PegHoleGeometry geometry;
  if (!header.contains("clearance")) return geometry;
  const nlohmann::json& clearance = header["clearance"];
  if (!clearance.is_number() || !(clearance.get<double>() > 0.0) ||
      !(clearance.get<double>() < kPegWidth)) {
    detail::fail(path, "line 1 (header)",
                 "\"clearance\" " + clearance.dump() + " is not a number in (0, " +
                     format_number(kPegWidth) + ") cm: fix the header or make the demos again");
  }
  geometry.clearance = clearance.get<double>();
  return geometry;
}

}  // namespace handcentric::sim

namespace handcentric::sim::detail {

std::vector<DemoRecord> parse_demo_records(const std::string& bytes, const std::string& source,
                                           const DemoFileTask& task, const DemoFileLimits& limits) {
  std::istringstream in(bytes);
  return read_demo_records(in, source, task, limits);
}

}  // namespace handcentric::sim::detail
