#include "handcentric/core/held_array.hpp"

#include <cmath>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/format.hpp"

namespace handcentric {

std::string HeldArray::describe() const {
  std::string out = "(";
  for (std::size_t i = 0; i < shape.size(); ++i)
    out += (i > 0 ? ", " : "") + std::to_string(shape[i]);
  if (shape.size() == 1) out += ",";
  return out + ") " + (float32 ? "float32" : "float64");
}

void HeldArray::validate(const std::string& name) const {
  std::int64_t count = 1;
  for (const std::int64_t size : shape) {
    if (size < 0)
      throw InvalidArgument("held array '" + name + "' has a negative size: " + describe());
    count *= size;
  }
  if (count != static_cast<std::int64_t>(values.size())) {
    throw InvalidArgument("held array '" + name + "' has shape " + describe() + " but " +
                          std::to_string(values.size()) + " values");
  }
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      throw InvalidArgument("held array '" + name + "' has a non-finite value at flat index " +
                            std::to_string(i) + ": " + format_number(values[i]) +
                            "; replace it (a depth image's missing pixels by 0, say)");
    }
  }
}

}  // namespace handcentric
