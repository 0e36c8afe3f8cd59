#pragma once
// Drawings of the 2D task (OpenCV imgproc, written as PNG on zlib), meant to be read at a
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
#include "handcentric/sim/rollout.hpp"
#include "handcentric/sim/scenes.hpp"

namespace handcentric::sim {

/// An 8-bit RGB image, row-major, 3 bytes per pixel.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;

  /// Pixels whose colour is within `tolerance` (per channel) of (r, g, b).
  int count_pixels(std::uint8_t r, std::uint8_t g, std::uint8_t b, int tolerance = 0) const;
};

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

/// Writes `image` as a PNG, atomically. Throws Error naming the path when it cannot.
void write_png(const std::string& path, const Image& image);

}  // namespace handcentric::sim
