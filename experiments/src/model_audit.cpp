#include "handcentric/experiments/model_audit.hpp"

#include <memory>
#include <mutex>

#include "handcentric/core/errors.hpp"
#include "handcentric/experiments/insert3d_image.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/props/audit.hpp"
#include "handcentric/props/checks/policy_audit.hpp"

namespace handcentric::experiments {

std::vector<props::Group> model_groups(const policy::PolicyConfig& config,
                                       const std::vector<props::Group>& groups, bool named,
                                       const std::string& model) {
  if (config.task != policy::kTaskPeg2d) return groups;
  std::vector<props::Group> kept;
  for (props::Group g : groups) {
    if (g == props::Group::rotation || g == props::Group::se3) {
      if (named) {
        const std::string name = props::to_string(g);
        throw InvalidArgument("--group " + name + ": " + model +
                              " is a model of the 2D task (peg2d), whose scenes lie in a plane "
                              "that " +
                              name + " tilts; audit it under translation, se2 or c8 (or all)");
      }
      continue;
    }
    kept.push_back(g);
  }
  return kept;
}

props::ClassifierOptions model_classifier_options(const policy::PolicyConfig& config,
                                                  props::ClassifierOptions classifier) {
  props::SceneShape& shape = classifier.check.shape;
  shape.min_history = shape.max_history = config.history_length;
  shape.min_hand_points = shape.max_hand_points = config.hand_points;
  shape.planar = config.task == policy::kTaskPeg2d;
  const props::View only =
      config.world_points > 0 ? props::View::third_person : props::View::eye_in_hand;
  std::vector<props::View> views;
  for (props::View v : classifier.views) {
    if (v == only) views.push_back(v);
  }
  if (views.empty()) {
    throw InvalidArgument("this model was trained with " + std::to_string(config.world_points) +
                          " world points, so it can only be audited in the " +
                          props::to_string(only) + " view; use --view " + props::to_string(only) +
                          " or all");
  }
  classifier.views = views;
  return classifier;
}

std::shared_ptr<policy::LearnedPolicy> load_audited_model(const std::string& path, bool floor) {
  const policy::LearnedPolicy model = policy::load_model(path);
  const bool image = model.config().task == policy::kTaskInsert3d &&
                     model.config().observation == policy::ObservationKind::image;
  if (floor && !image) {
    throw InvalidArgument("--floor puts a table in the hand camera's view, but " + path + " is a " +
                          policy::to_string(model.config().observation) + " model of " +
                          model.config().task +
                          ": give an image model of the 3D task (train --observation image)");
  }
  return std::make_shared<policy::LearnedPolicy>(with_task_camera(model, floor));
}

std::string audited_model_name(const std::string& path, const policy::LearnedPolicy& model) {
  return "model " + path + " (" + model.name() +
         (model.camera() ? ", " + model.camera()->name() : std::string()) + ")";
}

std::string table1_model_audit_json(const std::string& dir, const std::string& path, int cases) {
  // RapidCheck's search keeps process-wide state: Table 1's trainings run on several threads,
  // their audits one at a time.
  static std::mutex one_at_a_time;
  const std::lock_guard lock(one_at_a_time);
  auto model = load_audited_model(dir + "/" + path);
  props::AuditOptions audit;
  audit.groups = model_groups(model->config(), props::all_groups(), false, path);
  audit.views = {props::View::eye_in_hand};
  audit.cases = cases;
  props::ClassifierOptions classifier =
      model_classifier_options(model->config(), props::classifier_options(audit));
  classifier.in_distribution = false;
  props::Classification result =
      props::classify_policy(std::make_shared<props::SeededPolicy>(model), classifier);
  result.name = audited_model_name(path, *model);
  return props::policy_audit_json({result});
}

}  // namespace handcentric::experiments
