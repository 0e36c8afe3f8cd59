#include "handcentric/core/atomic_file.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "handcentric/core/errors.hpp"

namespace handcentric {

void write_file_atomically(const std::string& path, const std::string& bytes) {
  if (path.empty()) throw FileError("output path is empty; give a file name, e.g. out.jsonl");
  const std::string temporary = path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) {
      throw FileError("cannot write '" + path + "' (" + std::strerror(errno) +
                      "); check that its directory exists and is writable");
    }
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.flush();
    if (!out) {
      std::remove(temporary.c_str());
      throw FileError("cannot write '" + path + "' (write failed); check the free space");
    }
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::remove(temporary.c_str());
    throw FileError("cannot write '" + path + "' (" + error.message() +
                    "); check that it is not a directory and that its folder is writable");
  }
}

}  // namespace handcentric
