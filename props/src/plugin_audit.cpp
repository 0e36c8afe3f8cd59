#include "handcentric/props/plugin_audit.hpp"

#include <algorithm>
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
  const PolicyInterface& interface = capabilities.policy;
  if (!interface.hands.empty() && audit.observations) {
    throw InvalidArgument(
        "the plug-in's hello declares \"hands\", and --observations carry one hand's history; "
        "audit its hands on drawn scenes (leave --observations out)");
  }
  const ClassifierOptions classifier = plugin_classifier_options(audit, capabilities);
  PolicyPluginAudit out{{}, capabilities.cameras, interface};
  // The closed loop executes the first pose output and compares each output after it.
  std::optional<std::size_t> executed;
  for (std::size_t o = 0; o < interface.outputs.size() && !executed; ++o)
    if (interface.outputs[o].kind == OutputKind::pose) executed = o;
  const std::size_t count = std::max<std::size_t>(1, interface.outputs.size());
  for (std::size_t o = 0; o < count; ++o) {
    Classification result =
        interface.named()
            ? classify_policy(as_checked(std::make_shared<const PipeOutput>(plugin, o)), classifier)
            : classify_policy(as_checked(plugin), classifier);
    if (interface.named()) {
      result.output = interface.outputs[o];
      result.name += " (" + to_string(interface.outputs[o].kind) + ")";  // named by PipeOutput
    }
    if (setup.closed_loop) {
      ClosedLoopOptions loop = *setup.closed_loop;
      loop.start_episode = [plugin] { plugin->start_episode(); };
      const bool ahead = executed && *executed != o;
      loop.compared_from = ahead ? 1 : 0;
      const auto looped = as_checked(std::make_shared<const PipeOutput>(plugin, o, executed));
      for (const View view : audit.views) {
        for (const Group group : audit.groups) {
          Verdict verdict;
          try {
            verdict =
                check_policy_closed_loop(*looped, group, with_view(classifier.check, view), loop);
          } catch (...) {
            plugin->end_episode();
            throw;
          }
          plugin->end_episode();
          if (ahead) {
            verdict.note += std::string(verdict.note.empty() ? "" : "; ") +
                            interface.outputs[*executed].name + " executed, " +
                            interface.outputs[o].name + " compared";
          }
          result.verdicts.push_back(std::move(verdict));
        }
      }
    }
    out.results.push_back(std::move(result));
  }
  return out;
}

}  // namespace handcentric::props
