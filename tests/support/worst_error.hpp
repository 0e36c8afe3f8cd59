#pragma once
// The worst of a test's errors, for checks such as CHECK(worst <= tolerance). std::max(worst,
// error) returns worst when error is NaN, so a NaN error vanishes and the check passes; worst_of
// keeps the NaN, and every comparison with it fails.
#include <cmath>

namespace handcentric::test {

/// `error` if it is NaN or above `worst`, else `worst`: NaN from the first NaN error on.
inline double worst_of(double worst, double error) {
  return std::isnan(error) || error > worst ? error : worst;
}

}  // namespace handcentric::test
