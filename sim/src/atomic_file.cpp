#include "handcentric/sim/atomic_file.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <unistd.h>

#include "handcentric/core/errors.hpp"

namespace handcentric::sim {

void write_file_atomically(const std::string& path, const std::string& bytes) {
  if (path.empty()) throw InvalidArgument("output path is empty; pass a file name such as out.jsonl");
  const std::string temporary = path + ".tmp." + std::to_string(::getpid());
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) {
      throw Error("cannot write '" + path + "': cannot create '" + temporary +
                  "' (does the directory exist and is it writable?)");
    }
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.flush();
    if (!out) {
      std::remove(temporary.c_str());
      throw Error("cannot write '" + path + "': writing '" + temporary + "' failed (disk full?)");
    }
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::remove(temporary.c_str());
    throw Error("cannot write '" + path + "': rename from '" + temporary + "' failed: " + error.message());
  }
}

}  // namespace handcentric::sim
