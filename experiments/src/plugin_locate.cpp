// locate_plugin: a plug-in's stages asked through props::PipePolicy::staged_answers and decided
// by locate_watched (model_locate.cpp).
#include "handcentric/experiments/plugin_locate.hpp"

#include <memory>

#include "handcentric/core/errors.hpp"
#include "handcentric/props/checks/classifier.hpp"
#include "handcentric/props/transport/pipe_policy.hpp"

namespace handcentric::experiments {
namespace {

/// One staged answer as locate_watched reads it: the stages in the hello's order (a "poses"
/// stage's poses and their 16 x K values, a "features" stage's numbers as one column), and the
/// policy's chunk, its answer's output `chunk_output`.
WatchedAnswer watched_stages(props::PipePolicy::Staged staged,
                             const std::vector<props::PipelineStage>& stages,
                             std::size_t chunk_output) {
  WatchedAnswer out;
  out.chunk = std::move(staged.answer.at(chunk_output));
  for (std::size_t s = 0; s < stages.size(); ++s) {
    props::OutputValue& value = staged.stages.at(s);
    WatchedOutput output{stages[s].name, 0, stages[s].kind, {}, {}};
    if (stages[s].kind == LayerKind::poses) {
      output.values = poses_as_values(value.poses);
      output.poses = std::move(value.poses);
    } else {
      output.values = std::move(value.numbers);
    }
    out.outputs.push_back(std::move(output));
  }
  return out;
}

}  // namespace

std::vector<ModelLocation> locate_plugin(const std::string& command,
                                         const props::AuditOptions& audit,
                                         const props::PluginAuditSetup& setup) {
  auto plugin =
      std::make_shared<props::PipePolicy>(command, setup.timeout, setup.extra_poses, setup.scalars);
  if (audit.observations) plugin->use_probe(audit.observations->scenes.front());
  const props::PluginCapabilities& capabilities = plugin->capabilities();  // the handshake
  const props::PolicyInterface& interface = capabilities.policy;
  if (interface.stages.empty()) {
    throw InvalidArgument(
        "--locate decides the stages a plug-in's hello declares, and the hello of '" + command +
        "' declares no \"stages\"; declare them, e.g. serve_policy(policy, stages=[(\"to_hand\", "
        "\"features\"), (\"decode\", \"poses\")]) (docs/AUDIT.md, \"Localizing a break\")");
  }
  // The chunk: the first pose output (the one the closed loop executes), or the one chunk.
  std::size_t chunk_output = 0;
  while (chunk_output < interface.outputs.size() &&
         interface.outputs[chunk_output].kind != props::OutputKind::pose)
    ++chunk_output;
  if (chunk_output == interface.outputs.size()) chunk_output = 0;
  const std::vector<props::PipelineStage> stages = interface.stages;
  const WatchedPolicy ask = [plugin, stages, chunk_output](
                                const std::vector<const Scene*>& scenes,
                                const std::vector<const Eigen::VectorXd*>& noises) {
    std::vector<WatchedAnswer> out;
    for (props::PipePolicy::Staged& staged : plugin->staged_answers(scenes, noises))
      out.push_back(watched_stages(std::move(staged), stages, chunk_output));
    return out;
  };
  const props::ClassifierOptions classifier = props::plugin_classifier_options(audit, capabilities);
  std::vector<ModelLocation> out;
  for (const props::View view : audit.views) {
    for (const props::Group group : audit.groups) {
      out.push_back(locate_watched(ask, plugin->name(), plugin->noise_dimension(),
                                   props::with_view(classifier.check, view), group, view,
                                   "stages"));
    }
  }
  return out;
}

}  // namespace handcentric::experiments
