#include "handcentric/policy/dataset.hpp"

#include <string>

#include "handcentric/core/errors.hpp"
#include "handcentric/policy/image_source.hpp"

namespace handcentric::policy {

Dataset encode_scenes(const Representation& representation, const std::vector<Scene>& scenes,
                      int history_length, int chunk_length, const ImageSource* camera) {
  if (scenes.empty())
    throw InvalidScene("no training scenes: give at least one demonstration step");
  Dataset data;
  data.hand_points = static_cast<int>(scenes.front().hand_points.size());
  data.world_points = static_cast<int>(scenes.front().world_points.size());
  const Eigen::Index n = static_cast<Eigen::Index>(scenes.size());
  for (Eigen::Index j = 0; j < n; ++j) {
    const Scene& scene = scenes[static_cast<std::size_t>(j)];
    const std::string where = "training scene " + std::to_string(j) + ": ";
    try {
      scene.validate();
    } catch (const InvalidScene& error) {
      throw InvalidScene(where + error.what());
    }
    if (scene.history_length() != history_length || scene.chunk_length() != chunk_length) {
      throw InvalidScene(where + "history H = " + std::to_string(scene.history_length()) +
                         " and chunk K = " + std::to_string(scene.chunk_length()) +
                         ", but the policy is configured for H = " +
                         std::to_string(history_length) + ", K = " + std::to_string(chunk_length) +
                         ": cut the demonstrations with the same H and K");
    }
    if (static_cast<int>(scene.hand_points.size()) != data.hand_points ||
        static_cast<int>(scene.world_points.size()) != data.world_points) {
      throw InvalidScene(where + std::to_string(scene.hand_points.size()) + " eye-in-hand and " +
                         std::to_string(scene.world_points.size()) +
                         " world points, but scene 0 has " + std::to_string(data.hand_points) +
                         " and " + std::to_string(data.world_points) +
                         ": every scene needs the same points");
    }
    const Eigen::VectorXd a = representation.encode_actions(scene);
    const Eigen::VectorXd o = camera == nullptr
                                  ? representation.encode_observation(scene)
                                  : encode_image_observation(representation, *camera, scene);
    if (j == 0) {
      data.actions.resize(a.size(), n);
      data.observations.resize(o.size(), n);
    }
    data.actions.col(j) = a;
    data.observations.col(j) = o;
  }
  return data;
}

}  // namespace handcentric::policy
