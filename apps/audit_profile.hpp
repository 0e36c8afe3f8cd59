#pragma once
// `handcentric audit --profile GROUP --out DIR`: how far from equivariant (props/profile.hpp), for
// the built-ins, a plug-in (--exec, --policy-exec) or a trained model (--model); writes
// DIR/profile.json and DIR/profile.png (experiments/profile_plot.hpp).
#include <cstdint>
#include <string>
#include <vector>

#include "handcentric/props/checks/profile.hpp"
#include "handcentric/props/transport/plugin_connection.hpp"

namespace handcentric::apps {

struct ProfileCommand {
  std::string group;  ///< one group's name ("all" is refused: one plot per group)
  /// --view as given: one of "eye_in_hand", "third_person"; "all" means eye_in_hand
  std::vector<std::string> views;
  std::string out;                           ///< the folder to write
  std::vector<std::string> representations;  ///< built-ins; empty: all, and ActionFlow's target
  std::string exec, policy_exec, model;
  std::uint64_t seed = props::ProfileOptions{}.seed;
  int scenes = props::ProfileOptions{}.scenes;
  std::vector<double> sizes;  ///< empty: the group's defaults
  double timeout = props::kDefaultPluginTimeout;
};

/// Runs the profiles, then writes DIR/profile.json and DIR/profile.png (each atomically, both
/// computed before either is written) and prints one line per profile. Returns 0; throws
/// InvalidArgument for bad input.
int run_audit_profile(const ProfileCommand& command);

}  // namespace handcentric::apps
