#include "wire_arrays.hpp"

#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>

#include "handcentric/core/format.hpp"

namespace handcentric::props::wire {
namespace {

constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

// The value of each base64 character, -1 for the others ('=' included: it is padding).
constexpr std::array<signed char, 256> kValues = [] {
  std::array<signed char, 256> values{};
  for (auto& v : values) v = -1;
  for (int i = 0; i < 64; ++i) values[static_cast<unsigned char>(kAlphabet[i])] = i;
  return values;
}();

constexpr const char* kForm =
    "; an encoded array is {\"dtype\": \"float64\", \"shape\": [n, ...], \"data\": \"base64 of "
    "the elements, row-major, little-endian\"}";

std::size_t item_size(Dtype dtype) {
  switch (dtype) {
    case Dtype::float64:
      return 8;
    case Dtype::float32:
      return 4;
    case Dtype::uint8:
      return 1;
  }
  return 0;
}

void append_base64(std::string& out, const unsigned char* bytes, std::size_t n) {
  const std::size_t start = out.size();
  out.resize(start + 4 * ((n + 2) / 3));
  char* p = &out[start];
  std::size_t i = 0;
  for (; i + 3 <= n; i += 3) {
    const std::uint32_t v = (std::uint32_t{bytes[i]} << 16) | (std::uint32_t{bytes[i + 1]} << 8) |
                            std::uint32_t{bytes[i + 2]};
    *p++ = kAlphabet[v >> 18];
    *p++ = kAlphabet[(v >> 12) & 63];
    *p++ = kAlphabet[(v >> 6) & 63];
    *p++ = kAlphabet[v & 63];
  }
  if (i < n) {
    const bool two = i + 1 < n;
    const std::uint32_t v =
        (std::uint32_t{bytes[i]} << 16) | (two ? std::uint32_t{bytes[i + 1]} << 8 : 0);
    *p++ = kAlphabet[v >> 18];
    *p++ = kAlphabet[(v >> 12) & 63];
    *p++ = two ? kAlphabet[(v >> 6) & 63] : '=';
    *p++ = '=';
  }
}

// A character of a message: itself if printable, else its code.
std::string shown(char c) {
  const auto u = static_cast<unsigned char>(c);
  if (u >= 0x20 && u < 0x7f) return std::string("'") + c + "'";
  std::string text = "0x";  // appends: GCC 12 warns, falsely, on "0x" + std::string&&
  text += format_hex(u, 2);
  return text;
}

// Standard base64 (RFC 4648, section 4), padded: anything else is refused, not skipped, so that
// a corrupted line cannot decode to other numbers of the right length.
std::vector<unsigned char> decode_base64(const std::string& text, const std::string& where) {
  const std::string fix =
      "; \"data\" is standard base64 (A-Z a-z 0-9 + /, padded with = to a multiple of 4 "
      "characters), e.g. Python's base64.b64encode(array.astype('<f8').tobytes())";
  if (text.size() % 4 != 0) {
    throw FormatError(where + " whose \"data\" is not base64: " + std::to_string(text.size()) +
                      " characters, not a multiple of 4" + fix);
  }
  std::vector<unsigned char> out;
  out.reserve(text.size() / 4 * 3);
  for (std::size_t i = 0; i < text.size(); i += 4) {
    const bool last = i + 4 == text.size();
    // Padding: the last one or two characters of the last group only.
    const int pad = last ? (text[i + 3] == '=') + (text[i + 3] == '=' && text[i + 2] == '=') : 0;
    std::uint32_t v = 0;
    for (int j = 0; j < 4; ++j) {
      const char c = text[i + static_cast<std::size_t>(j)];
      const int value = j >= 4 - pad ? 0 : kValues[static_cast<unsigned char>(c)];
      if (value < 0) {
        throw FormatError(where + " whose \"data\" is not base64: " + shown(c) + " at character " +
                          std::to_string(i + static_cast<std::size_t>(j)) + fix);
      }
      v = (v << 6) | static_cast<std::uint32_t>(value);
    }
    out.push_back(static_cast<unsigned char>(v >> 16));
    if (pad < 2) out.push_back(static_cast<unsigned char>(v >> 8));
    if (pad < 1) out.push_back(static_cast<unsigned char>(v));
  }
  return out;
}

std::string shape_text(const std::vector<std::size_t>& shape) {
  std::string out = "[";
  for (std::size_t i = 0; i < shape.size(); ++i) {
    if (i > 0) out += ", ";
    out += std::to_string(shape[i]);
  }
  return out + "]";
}

}  // namespace

const char* dtype_name(Dtype dtype) {
  switch (dtype) {
    case Dtype::float64:
      return "float64";
    case Dtype::float32:
      return "float32";
    case Dtype::uint8:
      return "uint8";
  }
  return "?";
}

namespace {

// {"dtype": name, "shape": [...], "data": base64 of the elements' little-endian bytes}, for an
// element type T whose bits travel as the unsigned integer Bits of the same size.
template <class T, class Bits>
void append_array(std::string& out, const char* name, const std::vector<std::size_t>& shape,
                  const T* values) {
  static_assert(sizeof(T) == sizeof(Bits));
  std::size_t count = 1;
  for (std::size_t d : shape) count *= d;
  // Little-endian whatever the host's order: the shifts compile to plain stores on x86 and ARM.
  std::vector<unsigned char> bytes(count * sizeof(T));
  for (std::size_t i = 0; i < count; ++i) {
    Bits u;
    std::memcpy(&u, &values[i], sizeof(T));
    for (std::size_t b = 0; b < sizeof(T); ++b) bytes[sizeof(T) * i + b] = u >> (8 * b) & 0xff;
  }
  out += "{\"dtype\": \"";
  out += name;
  out += "\", \"shape\": ";
  out += shape_text(shape);
  out += ", \"data\": \"";
  append_base64(out, bytes.data(), bytes.size());
  out += "\"}";
}

}  // namespace

void append_float64_array(std::string& out, const std::vector<std::size_t>& shape,
                          const double* values) {
  append_array<double, std::uint64_t>(out, "float64", shape, values);
}

void append_float32_array(std::string& out, const std::vector<std::size_t>& shape,
                          const float* values) {
  append_array<float, std::uint32_t>(out, "float32", shape, values);
}

Array read_array(const nlohmann::json& value, const std::string& where) {
  if (!value.is_object() || value.size() != 3 || !value.contains("dtype") ||
      !value.contains("shape") || !value.contains("data")) {
    throw FormatError(where + " = " + one_line(value.dump(), 60) + ", not an encoded array" +
                      kForm);
  }
  Array array;
  const nlohmann::json& dtype = value["dtype"];
  if (dtype == "float64") {
    array.dtype = Dtype::float64;
  } else if (dtype == "float32") {
    array.dtype = Dtype::float32;
  } else if (dtype == "uint8") {
    array.dtype = Dtype::uint8;
  } else {
    throw FormatError(where + " of dtype " + one_line(dtype.dump(), 40) +
                      "; an encoded array's dtype is \"float64\", \"float32\" or \"uint8\" "
                      "(little-endian)");
  }
  const nlohmann::json& shape = value["shape"];
  constexpr std::size_t kMaxDimensions = 8;
  bool sizes = shape.is_array() && shape.size() <= kMaxDimensions;
  for (std::size_t i = 0; sizes && i < shape.size(); ++i)
    sizes = shape[i].is_number_unsigned() ||
            (shape[i].is_number_integer() && shape[i].get<long long>() >= 0);
  if (!sizes) {
    throw FormatError(where + " of shape " + one_line(shape.dump(), 40) +
                      ", not a list of at most 8 sizes (integers >= 0)" + kForm);
  }
  std::size_t count = 1;
  bool overflow = false;
  for (const auto& d : shape) {
    const auto size = d.get<unsigned long long>();
    array.shape.push_back(static_cast<std::size_t>(size));
    if (size != 0 && count > std::numeric_limits<std::size_t>::max() / 16 / size)
      overflow = true;
    else
      count *= static_cast<std::size_t>(size);
  }
  if (!value["data"].is_string())
    throw FormatError(where + " whose \"data\" is not a string" + kForm);
  const std::vector<unsigned char> bytes = decode_base64(value["data"].get<std::string>(), where);
  const std::size_t size = item_size(array.dtype);
  if (overflow || bytes.size() != count * size) {
    throw FormatError(where + " of shape " + shape_text(array.shape) + " and dtype " +
                      dtype_name(array.dtype) + ", which needs " +
                      (overflow ? std::string("more") : std::to_string(count * size)) +
                      " bytes, but \"data\" holding " + std::to_string(bytes.size()) +
                      "; send every element of the array, row-major, little-endian");
  }
  array.values.resize(count);
  const unsigned char* p = bytes.data();
  for (std::size_t i = 0; i < count; ++i, p += size) {
    if (array.dtype == Dtype::uint8) {
      array.values[i] = *p;
      continue;
    }
    std::uint64_t u = 0;
    for (std::size_t b = 0; b < size; ++b) u |= std::uint64_t{p[b]} << (8 * b);
    if (array.dtype == Dtype::float64) {
      std::memcpy(&array.values[i], &u, 8);
    } else {
      const auto u32 = static_cast<std::uint32_t>(u);
      float f;
      std::memcpy(&f, &u32, 4);
      array.values[i] = f;
    }
  }
  return array;
}

}  // namespace handcentric::props::wire
