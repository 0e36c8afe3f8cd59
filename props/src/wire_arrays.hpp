#pragma once
// Internal: arrays in the "base64" number encoding of the --exec protocol (docs/AUDIT.md,
// "Encoded numbers"): {"dtype": "float64" | "float32" | "uint8", "shape": [d0, d1, ...],
// "data": base64 of the elements, row-major, little-endian}. The dtype travels with each array
// so that the same form carries float32 and uint8 images as well as the protocol's float64
// numbers; the decoded elements are the bits that were encoded, so a double read this way is
// the one the JSON text of it (shortest round-trip) would have given.
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "handcentric/core/errors.hpp"

namespace handcentric::props::wire {

/// An encoded array that cannot be read. The transports report it as the plug-in's fault
/// (PluginError), the recorded observations as the file's (InvalidArgument).
class FormatError : public Error {
 public:
  using Error::Error;
};

enum class Dtype { float64, float32, uint8 };

/// "float64", "float32", "uint8".
const char* dtype_name(Dtype dtype);

/// Appends {"dtype": "float64", "shape": [...], "data": "..."} holding `values` (as many as
/// the product of `shape`), row-major.
void append_float64_array(std::string& out, const std::vector<std::size_t>& shape,
                          const double* values);

/// The same for float32 elements ({"dtype": "float32", ...}): images, which need no more.
void append_float32_array(std::string& out, const std::vector<std::size_t>& shape,
                          const float* values);

/// A decoded array: its dtype, shape and elements (every dtype widens to double exactly).
struct Array {
  Dtype dtype = Dtype::float64;
  std::vector<std::size_t> shape;
  std::vector<double> values;
};

/// Reads `value` as an encoded array. `where` begins each message and names the field, e.g.
/// `plug-in 'x' answered batched request 3 (item 1 of 4) with "actions"`. Throws FormatError
/// for an object that is not {"dtype", "shape", "data"}, a dtype other than the three, a shape
/// that is not a list of sizes, data that is not standard base64, or data whose length is not
/// the shape's. Non-finite elements are returned as they are: the caller says which are
/// allowed.
Array read_array(const nlohmann::json& value, const std::string& where);

/// Whether `value` has the form of an encoded array (an object), as opposed to JSON numbers.
inline bool is_encoded(const nlohmann::json& value) {
  return value.is_object();
}

}  // namespace handcentric::props::wire
