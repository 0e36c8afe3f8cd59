#include "handcentric/experiments/model_profile.hpp"

#include <filesystem>
#include <memory>

#include "handcentric/core/errors.hpp"
#include "handcentric/experiments/model_audit.hpp"
#include "handcentric/policy/c8_planar.hpp"
#include "handcentric/policy/learned_policy.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/props/checks/classifier.hpp"
#include "handcentric/props/noisy_policy.hpp"

namespace handcentric::experiments {

props::Profile profile_model(const std::string& path, props::Group group,
                             props::ProfileOptions options) {
  auto model = std::make_shared<policy::LearnedPolicy>(policy::load_model(path));
  const policy::PolicyConfig& config = model->config();
  // A peg2d model is profiled on planar scenes, under the groups that keep them planar
  // (model_audit.hpp).
  if (model_groups(config, {group}, false, path).empty())
    throw InvalidArgument("--profile " + props::to_string(group) + ": " + path +
                          " is a model of the 2D task (peg2d), whose scenes lie in a plane that " +
                          props::to_string(group) +
                          " tilts; profile it under translation, se2 or c8");
  // The model's own H, point counts and view (its world points or none), as `audit --model`.
  props::ClassifierOptions classifier;
  classifier.views = {props::View::eye_in_hand, props::View::third_person};
  options.shape = model_classifier_options(config, classifier).check.shape;
  // A planar C8 head is symmetric about its own centre, not the world origin.
  if (policy::is_c8_planar(config.head)) {
    const Eigen::Vector2d centre = policy::c8::centre_of(config);
    options.centre = Eigen::Vector3d(centre.x(), centre.y(), 0.0);
  }
  props::Profile profile = props::profile_policy(props::SeededPolicy(model), group, options);
  profile.name =
      "model " + std::filesystem::path(path).filename().string() + " (" + model->name() + ")";
  return profile;
}

}  // namespace handcentric::experiments
