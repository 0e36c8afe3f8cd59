#pragma once
// Compact, round-trippable text for numbers, vectors and matrices, used in error messages and
// witnesses (17 significant digits, so a printed value reproduces the double exactly).
#include <Eigen/Core>
#include <cstddef>
#include <string>

namespace handcentric {

/// A double with 17 significant digits ("nan", "inf" spelled out).
std::string format_number(double value);

/// The shortest text that reads back as exactly `value` ("0.3", not format_number's
/// "0.29999999999999999"): for values a person typed, in file names, flags and titles.
std::string format_shortest(double value);

/// A matrix as [[a, b, c], [d, e, f], ...]; a column vector as [a, b, c].
std::string format_matrix(const Eigen::Ref<const Eigen::MatrixXd>& matrix);

/// `text` as one line (newlines -> '|', trailing blanks dropped), cut at `limit` characters:
/// someone else's text (a plug-in's answer, a file's field) quoted inside an error message.
std::string one_line(std::string text, std::size_t limit = 200);

}  // namespace handcentric
