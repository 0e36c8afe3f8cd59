#include "handcentric/experiments/shell_quote.hpp"

namespace handcentric::experiments {

std::string shell_quote(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

}  // namespace handcentric::experiments
