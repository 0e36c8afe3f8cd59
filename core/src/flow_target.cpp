#include "handcentric/core/flow_target.hpp"

#include <cmath>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"
#include "handcentric/core/representations.hpp"

namespace handcentric {
namespace {

void require_noise(const Eigen::VectorXd& eps, Eigen::Index expected, double t,
                   const std::string& target) {
  if (eps.size() != expected) {
    throw InvalidArgument(target + ": noise eps has length " + std::to_string(eps.size()) +
                          ", expected " + std::to_string(expected) + " for this scene");
  }
  if (!eps.allFinite()) {
    throw InvalidArgument(target + ": noise eps has a non-finite entry");
  }
  if (!(t >= 0.0 && t <= 1.0)) {
    throw InvalidArgument(target + ": flow time t = " + format_number(t) + " is outside [0, 1]");
  }
}

Eigen::VectorXd concat(const Eigen::VectorXd& x_t, double t, const Eigen::VectorXd& observation) {
  Eigen::VectorXd input(x_t.size() + 1 + observation.size());
  input << x_t, t, observation;
  return input;
}

}  // namespace

RectifiedFlow::RectifiedFlow(std::shared_ptr<const Representation> representation)
    : representation_(std::move(representation)) {
  if (!representation_) throw InvalidArgument("RectifiedFlow needs a representation, got null");
}

std::string RectifiedFlow::name() const {
  return "rectified_flow(" + representation_->name() + ")";
}

Eigen::Index RectifiedFlow::noise_dimension(const Scene& scene) const {
  return representation_->encode_actions(scene).size();
}

FlowSample RectifiedFlow::operator()(const Scene& scene, const Eigen::VectorXd& eps,
                                     double t) const {
  const Eigen::VectorXd a = representation_->encode_actions(scene);
  require_noise(eps, a.size(), t, name());
  // eq. (5): x_t = t a + (1 - t) eps, regression target a - eps.
  const Eigen::VectorXd x_t = t * a + (1.0 - t) * eps;
  return {concat(x_t, t, representation_->encode_observation(scene)), a - eps};
}

Eigen::Index ActionFlowTarget::noise_dimension(const Scene& scene) const {
  return 3 * static_cast<Eigen::Index>(scene.world_T_hand_chunk.size());
}

FlowSample ActionFlowTarget::operator()(const Scene& scene, const Eigen::VectorXd& eps,
                                        double t) const {
  scene.validate();
  require_noise(eps, noise_dimension(scene), t, name());
  const Eigen::Index K = scene.chunk_length();
  Eigen::VectorXd x_t(3 * K), target(3 * K);
  for (Eigen::Index k = 0; k < K; ++k) {
    const RigidTransform& world_T_handk = scene.world_T_hand_chunk[static_cast<std::size_t>(k)];
    const Eigen::Vector3d eps_k = eps.segment<3>(3 * k);
    x_t.segment<3>(3 * k) = t * world_T_handk.translation() + (1.0 - t) * eps_k;  // eq. (27)
    // eq. (29) = eq. (28) with eq. (27) inserted: R_k^T (p_k - eps_k).
    target.segment<3>(3 * k) =
        world_T_handk.rotation().matrix().transpose() * (world_T_handk.translation() - eps_k);
  }
  return {concat(x_t, t, AbsoluteRepresentation().encode_observation(scene)), target};
}

}  // namespace handcentric
