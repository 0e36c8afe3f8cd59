#pragma once
// Flow targets: (scene, noise eps, time t) -> (network input, regression target).
//
//   RectifiedFlow(repr) : the rectified linear flow of eq. (5) on repr's action vector a:
//                         x_t = t a + (1 - t) eps, target u = a - eps,
//                         input = [x_t, t, repr.encode_observation(scene)].
//   ActionFlowTarget    : ActionFlow's field (Funk et al. [8]) on the translation part of
//                         absolute actions, eqs. (27)-(29): x_t = t p_k + (1 - t) eps_k,
//                         target u_k = R_k^T (p_k - eps_k); input = [x_t, t, world proprio,
//                         eye-in-hand points]. Only the translation flow is modelled, as in
//                         App. A.4, which shows that it alone breaks SE(3) invariance.
#include <Eigen/Core>
#include <memory>
#include <string>

#include "handcentric/core/representation.hpp"
#include "handcentric/core/scene.hpp"

namespace handcentric {

struct FlowSample {
  Eigen::VectorXd input;   ///< what the network sees
  Eigen::VectorXd target;  ///< what it regresses
};

class FlowTarget {
 public:
  virtual ~FlowTarget() = default;
  virtual std::string name() const = 0;
  /// Length of eps for this scene.
  virtual Eigen::Index noise_dimension(const Scene& scene) const = 0;
  /// Throws InvalidArgument for a wrong-length or non-finite eps, or t outside [0, 1].
  virtual FlowSample operator()(const Scene& scene, const Eigen::VectorXd& eps, double t) const = 0;
};

class RectifiedFlow final : public FlowTarget {
 public:
  /// Throws InvalidArgument for a null representation.
  explicit RectifiedFlow(std::shared_ptr<const Representation> representation);
  std::string name() const override;
  Eigen::Index noise_dimension(const Scene& scene) const override;
  FlowSample operator()(const Scene& scene, const Eigen::VectorXd& eps, double t) const override;

 private:
  std::shared_ptr<const Representation> representation_;
};

class ActionFlowTarget final : public FlowTarget {
 public:
  std::string name() const override { return "actionflow"; }
  Eigen::Index noise_dimension(const Scene& scene) const override;
  FlowSample operator()(const Scene& scene, const Eigen::VectorXd& eps, double t) const override;
};

}  // namespace handcentric
