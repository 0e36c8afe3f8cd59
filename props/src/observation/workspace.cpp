#include "handcentric/props/observation/workspace.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"

namespace handcentric::props {
namespace {

// The least side a workspace may have: below it no scene of the audit's smallest scale (1 cm)
// fits with room to move.
constexpr double kLeastSide = 1e-3;

bool inside(const Workspace& box, const Eigen::Vector3d& p) {
  return (p.array() >= box.min.array()).all() && (p.array() <= box.max.array()).all();
}

}  // namespace

void Workspace::validate() const {
  if (!min.allFinite() || !max.allFinite()) {
    throw InvalidArgument("a workspace's corners must be finite, got " + describe() +
                          "; e.g. --workspace -1,-1,0,1,1,1");
  }
  for (int axis = 0; axis < 3; ++axis) {
    if (!(max(axis) - min(axis) > kLeastSide)) {
      throw InvalidArgument("the workspace " + describe() + " is " +
                            format_number(max(axis) - min(axis)) + " m along " +
                            std::string(1, "xyz"[axis]) +
                            "; each side must be longer than 1 mm, min before max (e.g. "
                            "-1,-1,0,1,1,1: x, y, z of the low corner, then of the high one)");
    }
  }
}

Workspace Workspace::parse(const std::string& text) {
  std::vector<double> numbers;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      std::size_t used = 0;
      numbers.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw InvalidArgument("--workspace '" + text + "': '" + item +
                            "' is not a number; give six: x0,y0,z0,x1,y1,z1 in m, e.g. "
                            "-1,-1,0,1,1,1");
    }
  }
  if (numbers.size() != 6) {
    throw InvalidArgument("--workspace '" + text + "' has " + std::to_string(numbers.size()) +
                          " numbers; give six: x0,y0,z0,x1,y1,z1 in m, e.g. -1,-1,0,1,1,1");
  }
  Workspace box{Eigen::Vector3d(numbers[0], numbers[1], numbers[2]),
                Eigen::Vector3d(numbers[3], numbers[4], numbers[5])};
  box.validate();
  return box;
}

bool Workspace::contains(const Scene& scene) const {
  for (const RigidTransform& T : scene.world_T_hand_history)
    if (!inside(*this, T.translation())) return false;
  for (const RigidTransform& T : scene.world_T_hand_chunk)
    if (!inside(*this, T.translation())) return false;
  for (const Eigen::Vector3d& p : scene.world_points)
    if (!inside(*this, p)) return false;
  for (const auto& [name, T] : scene.extra_poses)
    if (!inside(*this, T.translation())) return false;
  return true;
}

std::string Workspace::describe() const {
  std::string out;
  for (int axis = 0; axis < 3; ++axis) {
    out += (axis ? " x [" : "[") + format_number(min(axis)) + ", " + format_number(max(axis)) + "]";
  }
  return out + " m";
}

double Workspace::room_for(Group group) const {
  validate();
  const Eigen::Vector3d half = 0.5 * (max - min);
  if (group == Group::rotation) {
    const double room = std::min((-min).minCoeff(), max.minCoeff());
    if (!(room > 0.0)) {
      throw InvalidArgument("the workspace " + describe() +
                            " does not contain the origin, about which the rotation group turns "
                            "the scene: give a box around the origin, or leave rotation out "
                            "(e.g. audit se3 alone)");
    }
    return room;
  }
  if (group == Group::c8) {
    const double room = std::min({-min.x(), -min.y(), max.x(), max.y(), half.z()});
    if (!(room > 0.0)) {
      throw InvalidArgument("the workspace " + describe() +
                            " does not contain the z axis, about which c8 turns the scene: give a "
                            "box around x = y = 0, or leave c8 out (e.g. audit se2 alone)");
    }
    return room;
  }
  return half.minCoeff();
}

std::string Workspace::verdict_note() const {
  return "decided inside the workspace " + describe() +
         ": every pose and point of o and of g o in it; nothing is said outside";
}

}  // namespace handcentric::props
