#pragma once
// Where a policy plug-in breaks the symmetry, stage by stage (`handcentric audit --policy-exec
// CMD --locate`): a plug-in whose hello declares the stages of its pipeline
// (props/transport/policy_interface.hpp, "stages") is asked the audit's own pointwise cases with
// "stages": true, and each stage's value is decided by its declared kind as model_locate.hpp
// decides a layer's output (locate_watched: the same cases, noise, rounding probe and rules).
// The rows are the stages in the hello's order; the policy's own chunk (its first pose output) is
// decided beside them as the audit's pointwise check decides it.
#include <string>
#include <vector>

#include "handcentric/experiments/model_locate.hpp"
#include "handcentric/props/audit.hpp"
#include "handcentric/props/plugin_audit.hpp"

namespace handcentric::experiments {

/// Starts `command` (props::PipePolicy, started as `setup` says), reads its hello and locates
/// its stages under each view and group of `audit`, on the cases of the plug-in's classifier
/// options (props::plugin_classifier_options, as audit_policy_plugin draws them). One location
/// per view and group, views outer. Throws InvalidArgument naming the fix when the hello
/// declares no stages, and what the plug-in's start, hello or answers throw.
std::vector<ModelLocation> locate_plugin(const std::string& command,
                                         const props::AuditOptions& audit,
                                         const props::PluginAuditSetup& setup = {});

}  // namespace handcentric::experiments
