#include "handcentric/props/observation/hands.hpp"

#include <algorithm>

#include "handcentric/core/errors.hpp"

namespace handcentric::props {
namespace {

std::string listed(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& name : names) out += (out.empty() ? "" : ", ") + name;
  return "(" + out + ")";
}

bool is_pose_of(const std::string& name, const std::string& hand) {
  const std::string now = hand_pose_name(hand, 0);
  return name == now || name.rfind(now + "@-", 0) == 0;
}

}  // namespace

std::string hand_pose_name(const std::string& hand, int steps_ago) {
  return kHandPosePrefix + hand + (steps_ago == 0 ? "" : "@-" + std::to_string(steps_ago));
}

bool is_hand_pose(const std::string& name) {
  return name.rfind(kHandPosePrefix, 0) == 0;
}

std::vector<RigidTransform> recorded_hand_history(const Scene& scene, const std::string& hand) {
  std::vector<RigidTransform> history;
  for (int k = 0;; ++k) {
    const std::string name = hand_pose_name(hand, k);
    const auto found = std::find_if(scene.extra_poses.begin(), scene.extra_poses.end(),
                                    [&](const auto& p) { return p.first == name; });
    if (found == scene.extra_poses.end()) break;
    history.push_back(found->second);
  }
  return history;
}

RecordedObservations recorded_with_hands(const RecordedObservations& data,
                                         const std::vector<std::string>& hands) {
  const std::vector<std::string> recorded = data.hands();
  if (recorded.empty()) {
    throw InvalidArgument("hands=" + listed(hands) + " but the observations of " + data.source +
                          " record one history: record history as {hand: (H+1, 4, 4)} per hand "
                          "(\"history/NAME\" in a .npz)");
  }
  std::vector<std::string> asked = hands;
  std::sort(asked.begin(), asked.end());
  if (asked != recorded) {
    throw InvalidArgument("hands=" + listed(hands) + " but the observations of " + data.source +
                          " record the histories of " + listed(recorded) +
                          ": name the recorded hands in hands=");
  }
  RecordedObservations out = data;
  const std::string& first = hands.front();
  for (Scene& scene : out.scenes) {
    scene.world_T_hand_history = recorded_hand_history(scene, first);
    auto& poses = scene.extra_poses;
    poses.erase(std::remove_if(poses.begin(), poses.end(),
                               [&](const auto& p) { return is_pose_of(p.first, first); }),
                poses.end());
  }
  out.validate();
  return out;
}

}  // namespace handcentric::props
