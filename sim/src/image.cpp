// Images (image.hpp); their PNG files are encoded by Cairo (canvas.hpp): OpenCV's imgcodecs
// would load ~130 shared libraries (DICOM, GDAL, OpenEXR, ...) at every start of a program that
// links it, while Cairo is loaded anyway for the figures' text.
#include "handcentric/sim/image.hpp"

#include <cstdlib>

#include "handcentric/core/atomic_file.hpp"
#include "handcentric/sim/canvas.hpp"

namespace handcentric::sim {

int Image::count_pixels(std::uint8_t r, std::uint8_t g, std::uint8_t b, int tolerance) const {
  int count = 0;
  for (std::size_t i = 0; i + 2 < rgb.size(); i += 3) {
    if (std::abs(rgb[i] - r) <= tolerance && std::abs(rgb[i + 1] - g) <= tolerance &&
        std::abs(rgb[i + 2] - b) <= tolerance) {
      ++count;
    }
  }
  return count;
}

void write_png(const std::string& path, const Image& image) {
  write_file_atomically(path, Canvas(image).png());
}

}  // namespace handcentric::sim
