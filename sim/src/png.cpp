// PNG encoding on zlib (png.hpp).
#include "png.hpp"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <limits>
#include <vector>

#include "handcentric/core/errors.hpp"

namespace handcentric::sim {
namespace {

constexpr int kChannels = 3;
constexpr int kMaxSide = 1 << 24;

void put_u32(std::string& out, std::uint32_t v) {
  out.push_back(static_cast<char>((v >> 24) & 0xff));
  out.push_back(static_cast<char>((v >> 16) & 0xff));
  out.push_back(static_cast<char>((v >> 8) & 0xff));
  out.push_back(static_cast<char>(v & 0xff));
}

// A chunk: length, type, data, then the CRC-32 of type and data (section 5.3).
void put_chunk(std::string& out, const char (&type)[5], const std::string& data) {
  put_u32(out, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = out.size();
  out.append(type, 4);
  out += data;
  uLong crc = crc32_z(0L, Z_NULL, 0);
  crc = crc32_z(crc, reinterpret_cast<const Bytef*>(out.data() + start), out.size() - start);
  put_u32(out, static_cast<std::uint32_t>(crc));
}

// Paeth's predictor (section 9.4): of left, up and up-left, the one nearest left + up - up-left.
int paeth(int a, int b, int c) {
  const int p = a + b - c;
  const int pa = std::abs(p - a);
  const int pb = std::abs(p - b);
  const int pc = std::abs(p - c);
  if (pa <= pb && pa <= pc) return a;
  return pb <= pc ? b : c;
}

// Row `row` filtered by filter type `type` into `out` (row bytes); `above` is the previous row,
// or zeros for the first.
void filter_row(int type, const std::uint8_t* row, const std::uint8_t* above, std::size_t bytes,
                std::uint8_t* out, PngPredictor predict) {
  for (std::size_t i = 0; i < bytes; ++i) {
    const int left = i >= kChannels ? row[i - kChannels] : 0;
    const int up_left = i >= kChannels ? above[i - kChannels] : 0;
    out[i] = static_cast<std::uint8_t>(row[i] - predict(type, left, above[i], up_left));
  }
}

}  // namespace

int png_prediction(int type, int left, int up, int up_left) {
  switch (type) {
    case 1:
      return left;
    case 2:
      return up;
    case 3:
      return (left + up) / 2;
    case 4:
      return paeth(left, up, up_left);
    default:
      return 0;
  }
}

std::string encode_png(const std::uint8_t* rgb, std::size_t size, int width, int height) {
  return encode_png_predicting(rgb, size, width, height, png_prediction);
}

std::string encode_png_predicting(const std::uint8_t* rgb, std::size_t size, int width, int height,
                                  PngPredictor predict) {
  if (width < 1 || height < 1 || width >= kMaxSide || height >= kMaxSide) {
    throw InvalidArgument("encode_png: a " + std::to_string(width) + " x " +
                          std::to_string(height) + " image: each side must be in [1, 2^24)");
  }
  const std::size_t row_bytes = static_cast<std::size_t>(width) * kChannels;
  if (size != row_bytes * static_cast<std::size_t>(height)) {
    throw InvalidArgument("encode_png: " + std::to_string(size) + " bytes of pixels for a " +
                          std::to_string(width) + " x " + std::to_string(height) +
                          " RGB image, which has " + std::to_string(row_bytes * height));
  }
  // Each row: its filter type byte, then the filtered bytes (section 9.2).
  std::vector<std::uint8_t> filtered((row_bytes + 1) * static_cast<std::size_t>(height));
  const std::vector<std::uint8_t> zeros(row_bytes, 0);
  std::array<std::vector<std::uint8_t>, 5> candidates;
  for (auto& c : candidates) c.resize(row_bytes);
  for (int y = 0; y < height; ++y) {
    const std::uint8_t* row = rgb + static_cast<std::size_t>(y) * row_bytes;
    const std::uint8_t* above = y == 0 ? zeros.data() : row - row_bytes;
    int best = 0;
    unsigned long best_cost = std::numeric_limits<unsigned long>::max();
    for (int type = 0; type < 5; ++type) {
      filter_row(type, row, above, row_bytes, candidates[type].data(), predict);
      unsigned long cost = 0;  // the bytes read as signed: small residuals cost little
      for (const std::uint8_t b : candidates[type]) cost += b < 128 ? b : 256 - b;
      if (cost < best_cost) {
        best_cost = cost;
        best = type;
      }
    }
    std::uint8_t* out = filtered.data() + static_cast<std::size_t>(y) * (row_bytes + 1);
    out[0] = static_cast<std::uint8_t>(best);
    std::copy(candidates[best].begin(), candidates[best].end(), out + 1);
  }
  if (filtered.size() > std::numeric_limits<uLong>::max() / 2) {
    throw InvalidArgument("encode_png: the image is too large for one zlib stream");
  }
  uLongf compressed_size = compressBound(static_cast<uLong>(filtered.size()));
  std::string compressed(compressed_size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(compressed.data()), &compressed_size, filtered.data(),
                static_cast<uLong>(filtered.size()), Z_DEFAULT_COMPRESSION) != Z_OK) {
    throw Error("encode_png: zlib could not compress the image's rows");
  }
  compressed.resize(compressed_size);

  std::string png("\x89PNG\r\n\x1a\n", 8);
  std::string header;
  put_u32(header, static_cast<std::uint32_t>(width));
  put_u32(header, static_cast<std::uint32_t>(height));
  header += std::string("\x08\x02\x00\x00\x00", 5);  // depth 8, RGB, deflate, filters, no interlace
  put_chunk(png, "IHDR", header);
  put_chunk(png, "IDAT", compressed);
  put_chunk(png, "IEND", std::string());
  return png;
}

}  // namespace handcentric::sim
