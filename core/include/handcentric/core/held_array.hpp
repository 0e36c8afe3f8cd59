#pragma once
// HeldArray: a named array of an observation that no global transform changes, because it moves
// with the hand (Sec. 3.2): an eye-in-hand image recorded in a dataset, a gripper's joint
// readings, a language instruction's token ids. A policy audited on a user's own data gets it
// unchanged in o and in g * o; it is read-only and shared, so that a scene's copies (g * o, the
// audit's perturbations) cost nothing and never differ in it.
#include <cstdint>
#include <string>
#include <vector>

namespace handcentric {

struct HeldArray {
  std::vector<std::int64_t> shape;  ///< row-major; {} is a single number
  std::vector<double> values;       ///< the product of shape's sizes, all finite
  bool float32 = false;             ///< handed to a policy as float32 (an image) or float64

  /// "(3, 48, 64) float32".
  std::string describe() const;

  /// Throws InvalidArgument naming `name`: a negative size, a size that does not match the
  /// values, a non-finite value.
  void validate(const std::string& name) const;
};

}  // namespace handcentric
