#pragma once
// Planted faults for the props suite (besides tests/core/mutants.hpp): each check below is also
// run on one of these and must fail there.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "handcentric/core/flow_target.hpp"
#include "handcentric/core/representations.hpp"
#include "../core/mutants.hpp"  // ForgetsRotationOnTranslation, UsesR0ForR0Transpose

namespace handcentric::test {

/// hand_centric whose decoder forgets R_0 on the translation: p_k = p_0 + t_k instead of
/// p_0 + R_0 t_k (the inverse of eq. 2 done wrong). Encodes correctly.
class DecoderForgetsR0 final : public Representation {
 public:
  std::string name() const override { return "mutant_decoder_forgets_R0"; }
  Eigen::VectorXd encode_actions(const Scene& scene) const override { return HandCentricRepresentation().encode_actions(scene); }
  Eigen::VectorXd encode_observation(const Scene& scene) const override {
    return HandCentricRepresentation().encode_observation(scene);
  }
  std::vector<RigidTransform> decode_actions(const Eigen::VectorXd& a, const RigidTransform& world_T_hand0) const override {
    std::vector<RigidTransform> chunk = HandCentricRepresentation().decode_actions(a, world_T_hand0);
    for (std::size_t k = 0; k < chunk.size(); ++k) {
      const Eigen::Vector3d p = world_T_hand0.translation() + a.segment<3>(6 * static_cast<Eigen::Index>(k));
      chunk[k] = RigidTransform(chunk[k].rotation(), p);
    }
    return chunk;
  }
};

/// ActionFlow's target (eq. 29) with biased noise eps + m, m = (0, 0, 2) per action: the source
/// distribution N(m, I) is not rotation invariant, so neither is the target in distribution.
class BiasedNoiseActionFlow final : public FlowTarget {
 public:
  std::string name() const override { return "mutant_biased_noise_actionflow"; }
  Eigen::Index noise_dimension(const Scene& scene) const override { return inner_.noise_dimension(scene); }
  FlowSample operator()(const Scene& scene, const Eigen::VectorXd& eps, double t) const override {
    Eigen::VectorXd biased = eps;
    for (Eigen::Index k = 0; 3 * k + 2 < biased.size(); ++k) biased(3 * k + 2) += 2.0;
    return inner_(scene, biased, t);
  }

 private:
  ActionFlowTarget inner_;
};

}  // namespace handcentric::test
