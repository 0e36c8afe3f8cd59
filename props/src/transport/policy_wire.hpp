#pragma once
// Internal: the JSON of a policy plug-in's interface (policy_interface.hpp): the hello's fields
// read, an observation's poses written in its state layout (per hand), an answer's outputs read
// in its action layout.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "handcentric/core/scene.hpp"
#include "handcentric/props/transport/plugin_protocol.hpp"
#include "handcentric/props/transport/policy_interface.hpp"

namespace handcentric::props::policy_wire {

/// The interface `hello` declares. PluginError naming the field, the value and the fix;
/// `answered` begins each message ("plug-in 'x' answered request 0").
PolicyInterface read_interface(const nlohmann::json& hello, const std::string& answered);

/// Puts the outputs that name no hand in the order of `names` (the hello's own order; the
/// hands stay first, in the order of its "hands").
void order_outputs(PolicyInterface& interface, const std::vector<std::string>& names);

/// Whether an observation's poses go out other than as 4x4 matrices (a state layout or hands).
bool writes_poses(const PolicyInterface& interface);

/// "history": ... [, "extra_poses": {...}] of `scene` under `interface` (writes_poses): every
/// pose in the state layout, the history per hand, the hands' own extra poses left out.
void append_poses(std::string& out, const Scene& scene, const PolicyInterface& interface,
                  NumberEncoding encoding);

/// Whether an answer is read by read_outputs (an action layout or named outputs).
bool reads_outputs(const PolicyInterface& interface);

/// The outputs of a policy answer under `interface`, in its order: "chunk" (one output) or
/// "outputs" ({name: value}). PluginError for a missing or unnamed entry, a pose that is not a
/// vector of the layout or that contradicts it (the numbers named), an invariant without numbers.
std::vector<OutputValue> read_outputs(const nlohmann::json& answer,
                                      const PolicyInterface& interface,
                                      const std::string& answered);

/// The stages of an answer to a request with "stages": true, in the hello's order: "stages":
/// {name: value}, a "poses" stage's value K poses in the action layout, a "features" stage's
/// numbers. PluginError for a missing "stages", a declared stage missing, an undeclared one, or
/// a value of the wrong form (named, with the form it must have).
std::vector<OutputValue> read_stage_values(const nlohmann::json& answer,
                                           const PolicyInterface& interface,
                                           const std::string& answered);

}  // namespace handcentric::props::policy_wire
