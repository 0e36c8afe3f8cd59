#include "handcentric/core/format.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace handcentric {

std::string format_number(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  return buffer;
}

std::string format_shortest(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

namespace {

// One printf conversion of one value (the only printf of the library's numbers).
template <class T>
std::string printed(const char* format, int precision, T value) {
  char buffer[400];  // %.Nf of 1e308 with N <= 17 fits
  std::snprintf(buffer, sizeof(buffer), format, precision, value);
  return buffer;
}

}  // namespace

std::string format_fixed(double value, int decimals) {
  return printed("%.*f", decimals, value);
}

std::string format_significant(double value, int digits) {
  return printed("%.*g", digits, value);
}

std::string format_scientific(double value, int decimals) {
  return printed("%.*e", decimals, value);
}

std::string format_hex(std::uint64_t value, int digits) {
  return printed("%0*llx", digits, static_cast<unsigned long long>(value));
}

std::string format_clock(double seconds) {
  const long s = static_cast<long>(seconds + 0.5);
  const std::string ss = printed("%0*ld", 2, s % 60);
  if (s < 3600) return std::to_string(s / 60) + ":" + ss;
  return std::to_string(s / 3600) + ":" + printed("%0*ld", 2, (s / 60) % 60) + ":" + ss;
}

std::string format_digits(double value, int digits) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  if (value == 0.0) return "0";  // and not "-0"
  return format_significant(value, std::clamp(digits, 1, 17));
}

double largest_magnitude(const Eigen::Ref<const Eigen::VectorXd>& vector) {
  return vector.size() > 0 ? vector.cwiseAbs().maxCoeff<Eigen::PropagateNaN>() : 0.0;
}

std::string format_readable(const Eigen::Ref<const Eigen::VectorXd>& vector, int digits,
                            double noise) {
  std::string text = "[";
  for (Eigen::Index i = 0; i < vector.size(); ++i) {
    if (i > 0) text += ", ";
    text += format_digits(std::abs(vector(i)) < noise ? 0.0 : vector(i), digits);
  }
  return text + "]";
}

std::string format_readable(const Eigen::Ref<const Eigen::VectorXd>& vector) {
  return format_readable(vector, 6, 1e-9 * (1.0 + largest_magnitude(vector)));
}

int digits_to_tell_apart(double a, double b, int at_least) {
  int digits = std::clamp(at_least, 1, 17);
  while (digits < 17 && a != b && format_digits(a, digits) == format_digits(b, digits)) ++digits;
  return digits;
}

std::string format_matrix(const Eigen::Ref<const Eigen::MatrixXd>& matrix) {
  auto row_text = [&](Eigen::Index r) {
    std::string text = "[";
    for (Eigen::Index c = 0; c < matrix.cols(); ++c) {
      if (c > 0) text += ", ";
      text += format_number(matrix(r, c));
    }
    return text + "]";
  };
  if (matrix.cols() == 1) {  // a column vector prints as one flat list
    std::string text = "[";
    for (Eigen::Index r = 0; r < matrix.rows(); ++r) {
      if (r > 0) text += ", ";
      text += format_number(matrix(r, 0));
    }
    return text + "]";
  }
  std::string text = "[";
  for (Eigen::Index r = 0; r < matrix.rows(); ++r) {
    if (r > 0) text += ", ";
    text += row_text(r);
  }
  return text + "]";
}

std::string one_line(std::string text, std::size_t limit) {
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' '))
    text.pop_back();
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = '|';
  }
  if (text.size() > limit) text = text.substr(0, limit) + "...";
  return text;
}

}  // namespace handcentric
