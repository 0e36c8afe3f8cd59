#pragma once
// A whole file's bytes, for the run directories' JSON and demo files.
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "handcentric/core/errors.hpp"

namespace handcentric::experiments {

/// The bytes of `path`. Throws FileError naming it when it cannot be opened.
inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError("cannot open '" + path.string() + "': check the path");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace handcentric::experiments
