#pragma once
// The sim's own bar, checked by the main report: the expert must solve (plan a valid demo for)
// and insert in closed loop at least kExpertBar of the train and of the OOD scenes. A learned
// policy's success means little if the expert that taught it fails where it is scored.
#include <cstdint>

#include "handcentric/sim/scenes.hpp"

namespace handcentric::sim {

/// Fraction of scenes the expert must solve, and of closed-loop expert rollouts that must
/// succeed, on each distribution (docs/SIM.md, "The expert").
constexpr double kExpertBar = 0.99;

/// The main report's check of the bar (its terminal section and its page): the expert's demos on
/// this many scenes per distribution and its closed-loop rollouts on this many, from this seed.
constexpr int kExpertBarScenes = 200;
constexpr int kExpertBarRollouts = 50;
constexpr std::uint64_t kExpertBarSeed = 1;

struct ExpertCheck {
  double solved_rate = 0.0;   ///< scenes with a valid demo (ExpertRun::solved_rate)
  double discard_rate = 0.0;  ///< invalid solutions among the optimizations run
  int rollout_success = 0;    ///< closed-loop expert rollouts that inserted the peg
  int rollouts = 0;
  /// Both rates at or above kExpertBar.
  bool passes() const {
    return solved_rate >= kExpertBar && rollout_success >= kExpertBar * rollouts;
  }
};

/// The expert's demos on scenes 0..scenes-1 of (distribution, seed) and its closed-loop rollouts
/// on scenes 0..rollouts-1 of the same stream. Throws InvalidArgument for a count below 1.
ExpertCheck check_expert(const SceneDistribution& distribution, int scenes, int rollouts,
                         std::uint64_t seed);

}  // namespace handcentric::sim
