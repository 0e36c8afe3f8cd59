// Trains a small hand-centric flow policy on synthetic scenes (a constant hand-frame motion),
// then checks eq. (4) on it with handcentric's policy audit: the outer hand-centric policy is
// SE(3)-equivariant whatever the network learned (Theorem 1). Exit status 0 when it holds.
#include <iostream>
#include <memory>
#include <random>

#include "handcentric/core/sampling.hpp"
#include "handcentric/policy/trainer.hpp"
#include "handcentric/props/checks/policy_audit.hpp"

int main() {
  using namespace handcentric;
  policy::PolicyConfig config;  // the library's defaults: a hand-centric flow head
  config.steps = 200;
  std::mt19937_64 rng(1);
  std::vector<Scene> scenes;
  for (int i = 0; i < 64; ++i)
    scenes.push_back(random_scene(rng, config.history_length, config.chunk_length, 0, 0, 1.0));
  auto trained = std::make_shared<policy::LearnedPolicy>(policy::train_policy(config, scenes, 1));
  props::CheckOptions options = props::eye_in_hand_options();
  options.shape.min_history = options.shape.max_history = trained->config().history_length;
  options.shape.max_hand_points = 0;
  options.shape.min_chunk = options.shape.max_chunk = trained->config().chunk_length;
  options.cases = 200;
  const props::SeededPolicy policy(trained);
  const props::Verdict verdict =
      props::check_policy_equivariance(policy, props::Group::se3, options);
  std::cout << trained->name() << ": "
            << (verdict.invariant ? "SE(3)-equivariant" : "NOT equivariant") << " on "
            << verdict.cases << " cases, largest error " << verdict.max_error << "\n";
  if (verdict.witness) std::cout << props::format_witness(*verdict.witness) << "\n";
  return verdict.invariant ? 0 : 1;
}
