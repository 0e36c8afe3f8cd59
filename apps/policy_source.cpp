#include "policy_source.hpp"

#include "handcentric/experiments/insert3d_image.hpp"
#include "handcentric/experiments/table2.hpp"
#include "handcentric/policy/learned_policy.hpp"
#include "handcentric/policy/model_file.hpp"
#include "handcentric/sim/policies.hpp"
#include "handcentric/sim/rollout.hpp"

namespace handcentric::apps {

LoadedPolicy load_chunk_policy(const std::string& model_path, const std::string& scripted_name,
                               const policy::SamplingOverrides& overrides) {
  LoadedPolicy loaded;
  if (model_path.empty()) {
    loaded.policy = sim::make_scripted_policy(scripted_name);
    return loaded;
  }
  auto model = std::make_unique<policy::LearnedPolicy>(policy::load_model(model_path, overrides));
  policy::require_task(*model, policy::kTaskPeg2d, model_path);  // the 2D rollouts' observations
  loaded.rollout_options =
      sim::RolloutOptions::for_policy(model->config().history_length, model->config().execute);
  loaded.policy = std::move(model);
  return loaded;
}

LoadedInsert3dPolicy load_insert3d_policy(const std::string& model_path,
                                          const policy::SamplingOverrides& overrides) {
  LoadedInsert3dPolicy loaded;
  if (model_path.empty()) {
    loaded.policy = std::make_shared<const sim::insert3d::ClosedLoopExpert>();
    return loaded;
  }
  auto model = std::make_shared<policy::LearnedPolicy>(policy::load_model(model_path, overrides));
  policy::require_task(*model, policy::kTaskInsert3d, model_path);
  loaded.rollout_options = experiments::insert3d_rollout_options(model->config());
  if (model->config().observation == policy::ObservationKind::image) {
    // Held, not a temporary: options() refers into the camera object.
    const auto camera = experiments::insert3d_camera_of(model->config());
    loaded.camera = camera->options().camera;
    loaded.rig = camera->rig();
    loaded.normals = camera->options().channels == experiments::Insert3dImageChannels::normals;
  }
  // Each 3D model with the input it was trained on: the hand camera's image, or the corners and
  // the slot points computed from them (cmd_train).
  loaded.policy = experiments::insert3d_model_policy(std::move(model));
  return loaded;
}

}  // namespace handcentric::apps
