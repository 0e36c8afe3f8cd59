#pragma once
// Text for numbers, vectors and matrices: round-trippable (17 significant digits, so a printed
// value reproduces the double exactly) for error messages, readable (a few digits, rounding
// noise as 0) for witnesses, whose exact doubles are in the JSON, and rounded to a given
// precision for tables, figures and progress lines. Every number the library prints goes
// through here.
#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>

namespace handcentric {

/// A double with 17 significant digits ("nan", "inf" spelled out).
std::string format_number(double value);

/// The shortest text that reads back as exactly `value` ("0.3", not format_number's
/// "0.29999999999999999"): for values a person typed, in file names, flags and titles.
std::string format_shortest(double value);

/// `decimals` digits after the point, as printf's %.Nf: format_fixed(0.875, 2) is "0.88".
std::string format_fixed(double value, int decimals);

/// `digits` significant digits, as printf's %.Ng: format_significant(0.000123456, 2) is
/// "0.00012", format_significant(1e-7, 2) is "1e-07".
std::string format_significant(double value, int digits);

/// One digit before the point and `decimals` after it, times a power of ten, as printf's %.Ne:
/// format_scientific(0.00123, 1) is "1.2e-03".
std::string format_scientific(double value, int decimals);

/// `value` in hexadecimal, lower case, zero-padded to at least `digits` digits.
std::string format_hex(std::uint64_t value, int digits);

/// A duration rounded to the second: "m:ss" under an hour, "h:mm:ss" from an hour on.
std::string format_clock(double seconds);

/// `value` with `digits` significant digits, clamped to [1, 17] ("nan", "inf" spelled out;
/// -0 as "0").
std::string format_digits(double value, int digits = 6);

/// `vector` as [a, b, c] with `digits` significant digits, each entry of magnitude below `noise`
/// printed as 0 (a NaN never is).
std::string format_readable(const Eigen::Ref<const Eigen::VectorXd>& vector, int digits,
                            double noise);

/// format_readable at 6 digits, with noise 1e-9 (1 + the largest magnitude): below it lies what
/// rounding leaves beside a real value (a rotation vector's other components at a half turn) and
/// what an audit's off-case move adds (1e-9 (1 + L) in double), the audit's own tolerance
/// REL (1 + L) having the same form.
std::string format_readable(const Eigen::Ref<const Eigen::VectorXd>& vector);

/// The largest magnitude of `vector`'s entries (NaN when one is NaN, 0 when it is empty).
double largest_magnitude(const Eigen::Ref<const Eigen::VectorXd>& vector);

/// The fewest significant digits, from `at_least` up to 17, at which format_digits prints `a`
/// and `b` apart (`at_least` when they are equal, 17 when even 17 does not).
int digits_to_tell_apart(double a, double b, int at_least = 6);

/// A matrix as [[a, b, c], [d, e, f], ...]; a column vector as [a, b, c].
std::string format_matrix(const Eigen::Ref<const Eigen::MatrixXd>& matrix);

/// `text` as one line (newlines -> '|', trailing blanks dropped), cut at `limit` characters:
/// someone else's text (a plug-in's answer, a file's field) quoted inside an error message.
std::string one_line(std::string text, std::size_t limit = 200);

}  // namespace handcentric
