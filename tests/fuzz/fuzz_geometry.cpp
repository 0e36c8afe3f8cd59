// libFuzzer target: the validating constructors of core/ fed raw doubles (every bit pattern:
// nan, inf, subnormals, huge and tiny values), which is what a matrix read from a user's file
// or a plug-in's reply is. Each must return a valid value or throw a typed handcentric::Error;
// a value it accepts must stay finite through the operations that follow (docs/RELIABILITY.md,
// item 5), or the target traps.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "handcentric/core/errors.hpp"
#include "handcentric/core/rigid_transform.hpp"
#include "handcentric/core/rotation.hpp"

namespace {

using handcentric::Error;
using handcentric::RigidTransform;
using handcentric::Rotation;

void require_finite(const Eigen::MatrixXd& m) {
  if (!m.allFinite()) __builtin_trap();
}

// A rotation that passed validation: what the library does with one must stay finite.
void exercise(const Rotation& R) {
  require_finite(R.matrix());
  require_finite(R.log());
  require_finite((R * R).matrix());
  require_finite(R.inverse().matrix());
  if (!std::isfinite(R.angle())) __builtin_trap();
}

// Translations are promised finite results up to 1e150 per coordinate (sums and products of
// two stay far from overflow); beyond that only the matrix itself is checked.
void exercise(const RigidTransform& T) {
  require_finite(T.matrix());
  if (T.translation().cwiseAbs().maxCoeff<Eigen::PropagateNaN>() > 1e150) return;
  require_finite(T.log());
  require_finite(T.inverse().matrix());
  require_finite((T * T.inverse()).matrix());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  double x[16] = {};
  std::memcpy(x, data, std::min(size, sizeof x));
  const Eigen::Matrix4d M = Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(x);
  try {
    exercise(RigidTransform::from_matrix(M));
  } catch (const Error&) {
  }
  try {
    exercise(Rotation::from_matrix(M.topLeftCorner<3, 3>()));
  } catch (const Error&) {
  }
  try {
    exercise(Rotation::nearest(M.topLeftCorner<3, 3>()));
  } catch (const Error&) {
  }
  try {
    exercise(Rotation::from_quaternion(x[0], x[1], x[2], x[3]));
  } catch (const Error&) {
  }
  try {
    exercise(Rotation::exp(Eigen::Vector3d(x[4], x[5], x[6])));
  } catch (const Error&) {
  }
  try {
    exercise(Rotation::about_z(x[7]));
  } catch (const Error&) {
  }
  try {
    exercise(RigidTransform::planar(x[8], x[9], x[10]));
  } catch (const Error&) {
  }
  return 0;
}
