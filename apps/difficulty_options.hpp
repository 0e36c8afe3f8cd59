#pragma once
// --workspace and --clearance, the 2D task's difficulty (sim/difficulty.hpp), as `demos`, `eval`
// and `table1` take them, and their refusal on the 3D task: one place for the options' text.
#include <CLI/CLI.hpp>

#include "handcentric/core/errors.hpp"
#include "handcentric/sim/difficulty.hpp"

namespace handcentric::apps {

inline void add_difficulty_options(CLI::App& cmd, sim::Difficulty& difficulty) {
  cmd.add_option("--workspace", difficulty.workspace_cm,
                 "2D task: side (cm) of the square the hole is placed in (the paper's 100; "
                 "demos, evaluation and table1 must use the same)")
      ->capture_default_str();
  cmd.add_option("--clearance", difficulty.clearance_cm,
                 "2D task: the hole's inner width minus the peg's (cm; the paper's 0.1)")
      ->capture_default_str();
}

/// Throws when --workspace or --clearance was given a non-default value for the 3D task.
inline void refuse_2d_difficulty(const sim::Difficulty& difficulty) {
  if (!difficulty.is_default()) {
    throw InvalidArgument("--workspace and --clearance are options of the 2D task (" +
                          difficulty.describe() +
                          " given); the 3D task's slot has its own geometry: drop them");
  }
}

}  // namespace handcentric::apps
