#pragma once
// Wilson score interval for a binomial success rate (Wilson 1927): unlike the normal
// approximation it stays inside [0, 1] and is not empty at 0 or n successes, which is where
// Table 1's cells live.
namespace handcentric::experiments {

struct Interval {
  double lo = 0.0;
  double hi = 0.0;
};

/// The 95% (z = 1.959964) Wilson interval of `successes` in `trials`. Throws InvalidArgument
/// for trials < 1 or successes outside 0..trials.
Interval wilson_interval(int successes, int trials, double z = 1.959964);

}  // namespace handcentric::experiments
