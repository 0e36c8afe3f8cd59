#pragma once
// The special functions of the tests and of their power figures, from Boost.Math. Only
// special_functions.cpp includes Boost, so it stays private to handcentric_props: neither the
// installed headers nor a downstream project see it. Student's t is public (statistics.hpp).
//
// Boost.Math's error policy there: every error Boost can raise (domain, pole, overflow,
// evaluation, rounding, indeterminate result) throws, none aborts or is returned as a NaN, and
// what it throws leaves as handcentric's own: InvalidArgument for a domain or pole error, Error
// for the others. Underflow is not an error: a tail probability below the smallest double is 0,
// as a p-value of an overwhelming difference should be. The callers' argument checks make every
// error impossible for the arguments the audit passes.

namespace handcentric::props::detail {

/// P(Z > z) for Z ~ N(0, 1): 1 at -inf, 0 at +inf. Throws InvalidArgument for NaN.
double normal_upper_tail(double z);

/// The z with P(Z > z) = p for Z ~ N(0, 1), 0 < p < 1. Throws InvalidArgument for p outside
/// [0, 1] and Error for p = 0 or 1 (z infinite).
double normal_upper_quantile(double p);

}  // namespace handcentric::props::detail
