#include "handcentric/experiments/witness_panel.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace handcentric::experiments {

sim::Image witness_panel(const CameraImage& image, double max_range) {
  constexpr int kScale = 4;
  sim::Image out;
  out.width = 2 * image.width * kScale + kScale;
  out.height = image.height * kScale;
  out.rgb.assign(static_cast<std::size_t>(out.width) * out.height * 3, 255);
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) {
      const int col = x / kScale, row = y / kScale;
      const std::size_t pixel = static_cast<std::size_t>(row) * image.width;
      std::uint8_t* to = &out.rgb[3 * (static_cast<std::size_t>(y) * out.width + x)];
      if (col < image.width) {
        for (int c = 0; c < 3; ++c)
          to[c] = static_cast<std::uint8_t>(
              std::lround(255.0 * std::clamp(image.rgb[3 * (pixel + col) + c], 0.0, 1.0)));
      } else if (col > image.width) {
        const double depth = image.depth[pixel + static_cast<std::size_t>(col - image.width - 1)];
        const auto shade = static_cast<std::uint8_t>(
            std::lround(255.0 * std::clamp(1.0 - depth / max_range, 0.0, 1.0)));
        to[0] = to[1] = to[2] = shade;
      }
    }
  }
  return out;
}

}  // namespace handcentric::experiments
