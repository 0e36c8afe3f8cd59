#include "handcentric/props/plugin_audit.hpp"

#include <memory>

#include "handcentric/props/checks/classifier.hpp"
#include "handcentric/props/checks/policy_audit.hpp"
#include "handcentric/props/transport/pipe_policy.hpp"
#include "handcentric/props/transport/pipe_representation.hpp"

namespace handcentric::props {

Classification audit_representation_plugin(const std::string& command, const AuditOptions& audit,
                                           const PluginAuditSetup& setup) {
  auto plugin = std::make_shared<PipeRepresentation>(command, setup.timeout, setup.extra_poses,
                                                     setup.scalars);
  // On recorded observations the handshake sends their first, so that the plug-in meets the
  // parts it will be sent (held arrays, extra poses) from its first request on.
  if (audit.observations) plugin->use_probe(audit.observations->scenes.front());
  const PluginCapabilities& capabilities = plugin->capabilities();  // the handshake
  ClassifierOptions classifier = plugin_classifier_options(audit, capabilities);
  classifier.observation = plugin->provides_observation();
  std::shared_ptr<const FlowTarget> flow;
  if (capabilities.flow) flow = std::make_shared<PipeFlowTarget>(plugin);
  // Batched requests, with the verdicts and JSON of one scene at a time (batch.hpp).
  return classify_representation(as_checked(plugin), classifier, flow);
}

PolicyPluginAudit audit_policy_plugin(const std::string& command, const AuditOptions& audit,
                                      const PluginAuditSetup& setup) {
  auto plugin =
      std::make_shared<PipePolicy>(command, setup.timeout, setup.extra_poses, setup.scalars);
  if (audit.observations) plugin->use_probe(audit.observations->scenes.front());
  const PluginCapabilities& capabilities = plugin->capabilities();  // the handshake
  const ClassifierOptions classifier = plugin_classifier_options(audit, capabilities);
  return {classify_policy(as_checked(plugin), classifier), capabilities.cameras};
}

}  // namespace handcentric::props
