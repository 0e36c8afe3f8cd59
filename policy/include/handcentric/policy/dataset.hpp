#pragma once
// Training data: scenes (history T_{-H..0}, chunk T_{1..K}, points) encoded by a representation
// into two matrices, one sample per column.
#include <Eigen/Core>
#include <vector>

#include "handcentric/core/representation.hpp"
#include "handcentric/core/scene.hpp"

namespace handcentric::policy {

struct Dataset {
  Eigen::MatrixXd actions;       ///< representation.encode_actions, one column per scene
  Eigen::MatrixXd observations;  ///< representation.encode_observation, one column per scene
  int hand_points = 0;
  int world_points = 0;
  Eigen::Index size() const { return actions.cols(); }
};

class ImageSource;

/// Encodes every scene; with a camera, each observation is encode_image_observation's
/// (proprioception, then the camera's image; image_source.hpp). Throws InvalidScene naming the
/// scene index and the fix for: no scenes, an invalid scene, a history length != H, a chunk length
/// != K, or point counts that differ from the first scene's (all samples of a policy share one
/// observation layout).
Dataset encode_scenes(const Representation& representation, const std::vector<Scene>& scenes,
                      int history_length, int chunk_length, const ImageSource* camera = nullptr);

}  // namespace handcentric::policy
