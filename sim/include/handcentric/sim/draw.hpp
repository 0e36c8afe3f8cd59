#pragma once
// Drawings of the 2D task (OpenCV imgproc, captions in Cairo text), meant to be read at a
// glance:
//   scene   : the hole (grey walls, orange opening corners = the eye-in-hand key points), the peg
//             at its start (blue outline), the hole's +y axis (thin line out of the opening);
//   demos   : every demo in its hole frame (all holes coincide), the hand's path (one colour per
//             demo) and the peg's outline every few steps, so diversity shows;
//   rollout : the hole, the peg's outline at every step (light to dark blue over time), the final
//             peg filled green on success, red on collision, grey on timeout; a caption with the
//             outcome, steps and clipped commands.
// World y points up in every image.
#include <cstdint>
#include <string>
#include <vector>

#include "handcentric/sim/demos.hpp"
#include "handcentric/sim/geometry.hpp"
#include "handcentric/sim/image.hpp"
#include "handcentric/sim/rollout.hpp"
#include "handcentric/sim/scenes.hpp"

namespace handcentric::sim {

/// The colours the drawings use for the outcome (tests look for them).
constexpr std::uint8_t kSuccessRgb[3] = {40, 170, 60};
constexpr std::uint8_t kCollisionRgb[3] = {220, 30, 30};

/// Throws InvalidArgument for a size outside [64, 4096].
Image draw_scene(const TaskScene& scene, const PegHoleGeometry& geometry = PegHoleGeometry(),
                 int size = 800);
Image draw_demos(const std::vector<Demo>& demos,
                 const PegHoleGeometry& geometry = PegHoleGeometry(), int size = 800);
Image draw_rollout(const TaskScene& scene, const Rollout& rollout,
                   const PegHoleGeometry& geometry = PegHoleGeometry(), int size = 800);

}  // namespace handcentric::sim
