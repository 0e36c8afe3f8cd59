// write_png's files (Cairo's encoder, sim/src/image.cpp) read back by a decoder written here
// from the PNG specification (chunks and their CRCs, IHDR, one zlib stream, the five row filters
// undone): the pixels come back bit for bit on images whose rows suit different filters, and a
// damaged file or a changed pixel is seen.
#include <zlib.h>

#include <catch2/catch.hpp>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <string>
#include <unistd.h>
#include <utility>
#include <vector>

#include "handcentric/core/errors.hpp"
#include "handcentric/sim/draw.hpp"
#include "handcentric/sim/scenes.hpp"

using namespace handcentric;
using namespace handcentric::sim;

namespace {

std::uint32_t png_read_u32(const std::string& bytes, std::size_t at) {
  REQUIRE(at + 4 <= bytes.size());
  return (std::uint32_t{static_cast<std::uint8_t>(bytes[at])} << 24) |
         (std::uint32_t{static_cast<std::uint8_t>(bytes[at + 1])} << 16) |
         (std::uint32_t{static_cast<std::uint8_t>(bytes[at + 2])} << 8) |
         std::uint32_t{static_cast<std::uint8_t>(bytes[at + 3])};
}

struct PngDecoded {
  Image image;
  std::set<int> filters;  // the row filter types the file used
};

// Decodes an 8-bit RGB, non-interlaced PNG; throws std::runtime_error on anything else or on
// a chunk whose CRC does not match.
PngDecoded png_decode(const std::string& bytes) {
  if (bytes.compare(0, 8, std::string("\x89PNG\r\n\x1a\n", 8)) != 0)
    throw std::runtime_error("no PNG signature");
  std::size_t at = 8;
  PngDecoded decoded;
  std::string idat;
  bool ended = false;
  while (!ended) {
    const std::uint32_t length = png_read_u32(bytes, at);
    if (at + 12 + length > bytes.size()) throw std::runtime_error("a chunk runs past the end");
    const std::string type = bytes.substr(at + 4, 4);
    const std::string data = bytes.substr(at + 8, length);
    const uLong crc =
        crc32_z(0L, reinterpret_cast<const Bytef*>(bytes.data() + at + 4), length + 4);
    if (crc != png_read_u32(bytes, at + 8 + length)) throw std::runtime_error("bad CRC in " + type);
    if (type == "IHDR") {
      decoded.image.width = static_cast<int>(png_read_u32(data, 0));
      decoded.image.height = static_cast<int>(png_read_u32(data, 4));
      if (data.substr(8) != std::string("\x08\x02\x00\x00\x00", 5))
        throw std::runtime_error("not 8-bit RGB without interlace");
    } else if (type == "IDAT") {
      idat += data;
    } else if (type == "IEND") {
      ended = true;
    }
    at += 12 + length;
  }
  const std::size_t row = static_cast<std::size_t>(decoded.image.width) * 3;
  const std::size_t rows = static_cast<std::size_t>(decoded.image.height);
  std::vector<std::uint8_t> raw((row + 1) * rows);
  uLongf raw_size = raw.size();
  if (uncompress(raw.data(), &raw_size, reinterpret_cast<const Bytef*>(idat.data()), idat.size()) !=
          Z_OK ||
      raw_size != raw.size())
    throw std::runtime_error("the zlib stream is not the image's rows");
  std::vector<std::uint8_t>& out = decoded.image.rgb;
  out.assign(row * rows, 0);
  for (std::size_t y = 0; y < rows; ++y) {
    const int filter = raw[y * (row + 1)];
    decoded.filters.insert(filter);
    for (std::size_t i = 0; i < row; ++i) {
      const int a = i >= 3 ? out[y * row + i - 3] : 0;
      const int b = y > 0 ? out[(y - 1) * row + i] : 0;
      const int c = i >= 3 && y > 0 ? out[(y - 1) * row + i - 3] : 0;
      int predicted = 0;
      if (filter == 1) predicted = a;
      if (filter == 2) predicted = b;
      if (filter == 3) predicted = (a + b) / 2;
      if (filter == 4) {
        const int p = a + b - c;
        const int pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
        predicted = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      if (filter > 4) throw std::runtime_error("filter type " + std::to_string(filter));
      out[y * row + i] = static_cast<std::uint8_t>(raw[y * (row + 1) + 1 + i] + predicted);
    }
  }
  return decoded;
}

std::string png_path() {
  return (std::filesystem::temp_directory_path() /
          ("handcentric_test_png_" + std::to_string(::getpid()) + ".png"))
      .string();
}

std::string png_written(const Image& image) {
  const std::string path = png_path();
  write_png(path, image);
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::filesystem::remove(path);
  return bytes;
}

// Noise, flat bands, horizontal and vertical ramps and a diagonal: rows on which each of the
// five filters is the smallest.
Image png_test_image(int width, int height, std::uint32_t seed) {
  std::mt19937 random(seed);
  Image image{width, height,
              std::vector<std::uint8_t>(static_cast<std::size_t>(width) * height * 3)};
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int ch = 0; ch < 3; ++ch) {
        const int band = (y / 4) % 5;
        int v = 0;
        if (band == 0) v = static_cast<int>(random() % 256);
        if (band == 1) v = 40 * ch + 7;
        if (band == 2) v = 3 * x + ch;
        if (band == 3) v = 5 * y + 11 * ch;
        if (band == 4) v = 2 * (x + y) + static_cast<int>(random() % 3);
        image.rgb[(static_cast<std::size_t>(y) * width + x) * 3 + ch] =
            static_cast<std::uint8_t>(v);
      }
    }
  }
  return image;
}

// Sizes from one pixel to rows longer than 256 bytes.
const std::vector<std::pair<int, int>> kPngTestSizes = {
    {1, 1}, {2, 3}, {37, 20}, {64, 48}, {257, 41}};

}  // namespace

TEST_CASE("png_files_decode_to_their_pixels_bit_for_bit", "[unit]") {
  for (const auto& [width, height] : kPngTestSizes) {
    INFO(width << " x " << height);
    const Image image = png_test_image(width, height, static_cast<std::uint32_t>(width * height));
    const std::string bytes = png_written(image);
    const PngDecoded decoded = png_decode(bytes);
    CHECK(decoded.image.width == width);
    CHECK(decoded.image.height == height);
    CHECK(decoded.image.rgb == image.rgb);
    CHECK(png_written(image) == bytes);  // the same pixels, the same bytes
  }
  // A drawing as the command writes it.
  const Image scene =
      draw_scene(sample_scene(SceneDistribution::train(), 1, 0), PegHoleGeometry(), 200);
  CHECK(png_decode(png_written(scene)).image.rgb == scene.rgb);
}

TEST_CASE("mutant_png_a_damaged_file_or_a_changed_pixel_is_seen", "[unit]") {
  const Image image = png_test_image(37, 20, 5);
  std::string bytes = png_written(image);
  // A flipped bit inside the IDAT chunk's data (10 bytes past its type): its CRC no longer
  // matches.
  std::string damaged = bytes;
  const std::size_t idat = bytes.find("IDAT");
  REQUIRE(idat != std::string::npos);
  damaged[idat + 4 + 10] ^= 0x10;
  CHECK_THROWS_WITH(png_decode(damaged), Catch::Contains("bad CRC in IDAT"));
  Image changed = image;
  changed.rgb[100] ^= 1;
  CHECK(png_decode(png_written(changed)).image.rgb != image.rgb);
  // What cannot be encoded is refused before anything is written.
  CHECK_THROWS_AS(write_png(png_path(), Image{3, 2, std::vector<std::uint8_t>(17)}),
                  InvalidArgument);
  CHECK_FALSE(std::filesystem::exists(png_path()));
}
