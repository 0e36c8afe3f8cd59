#include "handcentric/proofs/flows.hpp"

#include "handcentric/core/errors.hpp"
#include "handcentric/proofs/rational_rotation.hpp"

namespace handcentric::proofs::flows {
namespace {

const ExactPose& hand0(const ExactScene& scene) {
  if (scene.history.empty()) {
    throw InvalidScene("exact scene has an empty history; put T_0 in history[0]");
  }
  return scene.history.front();
}

const ExactPose& hand_past(const ExactScene& scene) {
  if (scene.history.size() < 2) {
    throw InvalidScene("exact scene has no past pose T_{-h}; put it in history[1]");
  }
  return scene.history[1];
}

const ExactPose& hand_k(const ExactScene& scene) {
  if (scene.chunk.empty())
    throw InvalidScene("exact scene has an empty chunk; put T_k in chunk[0]");
  return scene.chunk.front();
}

}  // namespace

GiNaC::matrix absolute_translation(const ExactScene& scene, const GiNaC::matrix& eps) {
  return hand_k(scene).p.sub(eps);
}

GiNaC::matrix absolute_rotation_matrix(const ExactScene& scene) {
  return hand_k(scene).R;
}

GiNaC::matrix relative_translation(const ExactScene& scene, const GiNaC::matrix& eps) {
  return hand_k(scene).p.sub(hand0(scene).p).sub(eps);
}

GiNaC::matrix relative_rotation_matrix(const ExactScene& scene) {
  return hand0(scene).R.transpose().mul(hand_k(scene).R);
}

GiNaC::matrix relative_diff_rotation(const ExactScene& scene, const GiNaC::matrix& eps) {
  return exact_rotation_vector(hand_k(scene).R).sub(exact_rotation_vector(hand0(scene).R)).sub(eps);
}

GiNaC::matrix hand_centric_translation(const ExactScene& scene, const GiNaC::matrix& eps) {
  const ExactPose& world_T_hand0 = hand0(scene);
  return world_T_hand0.R.transpose().mul(hand_k(scene).p.sub(world_T_hand0.p)).sub(eps);
}

GiNaC::matrix hand_centric_rotation_matrix(const ExactScene& scene) {
  return hand0(scene).R.transpose().mul(hand_k(scene).R);
}

GiNaC::matrix hand_centric_proprioception(const ExactScene& scene) {
  const ExactPose hand0_T_handpast = hand0(scene).inverse() * hand_past(scene);
  return hand0_T_handpast.entries();
}

GiNaC::matrix inner_policy_input(const ExactScene& scene) {
  if (scene.hand_points.empty()) throw InvalidScene("exact scene has no eye-in-hand point");
  return stack(hand_centric_proprioception(scene), scene.hand_points.front());
}

GiNaC::matrix inner_policy_input_third_person(const ExactScene& scene) {
  if (scene.world_points.empty()) throw InvalidScene("exact scene has no world point");
  return stack(hand_centric_proprioception(scene), scene.world_points.front());
}

GiNaC::matrix actionflow_translation(const ExactScene& scene, const GiNaC::matrix& eps) {
  const ExactPose& world_T_handk = hand_k(scene);
  return world_T_handk.R.transpose().mul(world_T_handk.p.sub(eps));
}

}  // namespace handcentric::proofs::flows
