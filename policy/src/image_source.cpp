#include "handcentric/policy/image_source.hpp"

namespace handcentric::policy {

Eigen::VectorXd encode_image_observation(const Representation& representation,
                                         const ImageSource& camera, const Scene& observation) {
  observation.validate_observation();
  // The points reach the policy through the camera only.
  Scene proprioception = observation;
  proprioception.hand_points.clear();
  proprioception.world_points.clear();
  const Eigen::VectorXd proprio = representation.encode_observation(proprioception);
  Eigen::VectorXd out(proprio.size() + camera.shape().size());
  out.head(proprio.size()) = proprio;
  camera.render(observation, out.tail(camera.shape().size()));
  return out;
}

}  // namespace handcentric::policy
