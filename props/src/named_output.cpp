#include "handcentric/props/named_output.hpp"

#include <algorithm>

#include "handcentric/core/errors.hpp"

namespace handcentric::props {

std::string to_string(OutputKind kind) {
  return kind == OutputKind::pose ? "pose" : "invariant";
}

std::optional<OutputKind> parse_output_kind(const std::string& text) {
  if (text == "pose") return OutputKind::pose;
  if (text == "invariant") return OutputKind::invariant;
  return std::nullopt;
}

std::vector<RigidTransform> invariant_as_poses(const double* u, std::size_t count,
                                               const RigidTransform& T0) {
  std::vector<RigidTransform> poses;
  for (std::size_t j = 0; j < count; j += 3) {
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    for (std::size_t d = 0; d < 3 && j + d < count; ++d) position(static_cast<int>(d)) = u[j + d];
    poses.push_back(T0 * RigidTransform::from_translation(position));
  }
  return poses;
}

std::vector<NamedOutput> outputs_with_hands(const std::vector<std::string>& hands,
                                            const std::vector<NamedOutput>& declared,
                                            const std::string& keyword) {
  std::vector<NamedOutput> outputs;
  for (const std::string& hand : hands) outputs.push_back({hand, OutputKind::pose});
  for (const NamedOutput& output : declared) {
    const bool is_hand = std::count(hands.begin(), hands.end(), output.name) > 0;
    if (is_hand && output.kind != OutputKind::pose) {
      throw InvalidArgument(keyword + "[\"" + output.name + "\"] is '" + to_string(output.kind) +
                            "', but '" + output.name + "' is a hand: its chunk is a \"pose\"");
    }
    if (!is_hand) outputs.push_back(output);
  }
  return outputs;
}

std::vector<RigidTransform> other_hand_history(const Scene& scene, const std::string& hand) {
  const std::string pose_name = kHandPosePrefix + hand;
  const auto found = std::find_if(scene.extra_poses.begin(), scene.extra_poses.end(),
                                  [&](const auto& p) { return p.first == pose_name; });
  if (found == scene.extra_poses.end())
    throw InvalidArgument("the scene has no pose '" + pose_name + "' for hand " + hand);
  // S_k = S_0 T_0^-1 T_k: the other hand moves as the first one does.
  const RigidTransform S0_T_T0 = found->second * scene.world_T_hand_history.front().inverse();
  std::vector<RigidTransform> history;
  for (const RigidTransform& T : scene.world_T_hand_history) history.push_back(S0_T_T0 * T);
  return history;
}

}  // namespace handcentric::props
