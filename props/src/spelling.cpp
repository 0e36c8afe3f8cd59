#include "handcentric/props/spelling.hpp"

#include <algorithm>

namespace handcentric::props {

std::string Spelling::option(const std::string& name) const {
  if (!command_line) return name;
  std::string flag = name;
  std::replace(flag.begin(), flag.end(), '_', '-');
  return "--" + flag;
}

std::string Spelling::with_value(const std::string& name, const std::string& value,
                                 bool quoted) const {
  if (command_line) return option(name) + " " + value;
  return name + "=" + (quoted ? "\"" + value + "\"" : value);
}

}  // namespace handcentric::props
