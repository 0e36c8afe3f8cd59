#pragma once
// The audit of a plug-in, a map in any language over the pipe (docs/AUDIT.md, "--exec"): the
// process started, its hello read, the classifier set up from the hello and the checks run on
// it, one way for every front end that audits a plug-in (`handcentric audit --exec` and
// `--policy-exec`, the conventions' table).
#include <optional>
#include <string>
#include <vector>

#include "handcentric/props/audit.hpp"
#include "handcentric/props/checks/closed_loop.hpp"
#include "handcentric/props/observation/camera_rig.hpp"
#include "handcentric/props/transport/plugin_connection.hpp"
#include "handcentric/props/transport/policy_interface.hpp"

namespace handcentric::props {

/// How a plug-in is started and what it is sent besides the scene.
struct PluginAuditSetup {
  double timeout = kDefaultPluginTimeout;  ///< seconds to wait for each answer
  /// Names of world-frame poses and of scalars sent with every scene, besides those its hello
  /// asks for (`--extra-poses`, `--scalars`).
  std::vector<std::string> extra_poses, scalars;
  /// A policy's closed-loop audit beside its single calls (`--episodes`): each rollout is an
  /// episode of its requests (policy_interface.hpp, "episodes"). None: single calls only.
  std::optional<ClosedLoopOptions> closed_loop;
};

/// Audits the representation plug-in `command` (run by /bin/sh -c) under `audit`: its hello
/// read first (on the first recorded observation when audit.observations has some), the
/// classifier options of that hello (plugin_classifier_options), its own flow target when it
/// declares one, and batched requests with prefetch passes when it answers batches (as_checked).
/// Throws what the plug-in's start, hello or answers throw (PluginError, InvalidArgument).
Classification audit_representation_plugin(const std::string& command, const AuditOptions& audit,
                                           const PluginAuditSetup& setup = {});

/// A whole policy's audit over the pipe: one result per output its hello names (its hands, then
/// its other outputs; one result when it answers a chunk), the cameras its hello declares (the
/// rig that rendered the images it was shown; none when it sees no cameras) and the rest of
/// its interface (layouts, rng, episodes).
struct PolicyPluginAudit {
  std::vector<Classification> results;
  std::optional<CameraRig> cameras;
  PolicyInterface interface;
};

/// Audits the whole-policy plug-in `command` (eq. 4) as audit_representation_plugin does a
/// representation (no flow target: a policy answers chunks): each output as a map of its own
/// (named_output.hpp), on the same cases; with setup.closed_loop, each output's closed-loop
/// verdicts too, the first pose output executed.
PolicyPluginAudit audit_policy_plugin(const std::string& command, const AuditOptions& audit,
                                      const PluginAuditSetup& setup = {});

}  // namespace handcentric::props
