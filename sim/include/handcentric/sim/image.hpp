#pragma once
// An 8-bit RGB image: the drawings' pixels and the camera images shown to image policies,
// written as PNG (lossless, so a file decodes to the same pixels).
#include <cstdint>
#include <string>
#include <vector>

namespace handcentric::sim {

/// An 8-bit RGB image, row-major, 3 bytes per pixel.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;

  /// Pixels whose colour is within `tolerance` (per channel) of (r, g, b).
  int count_pixels(std::uint8_t r, std::uint8_t g, std::uint8_t b, int tolerance = 0) const;
};

/// Writes `image` as an 8-bit RGB PNG (Cairo's encoder, canvas.hpp), atomically. Throws
/// InvalidArgument for an empty image or a pixel buffer of the wrong size, Error naming the path
/// when it cannot write.
void write_png(const std::string& path, const Image& image);

}  // namespace handcentric::sim
