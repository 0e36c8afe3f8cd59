#include "handcentric/core/atomic_file.hpp"

#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <thread>

#include "handcentric/core/errors.hpp"

namespace handcentric {

namespace {

// A planted fault, for the test that kills writers (tests/reliability/kill_writers.sh) to show
// that it catches a partial file: with HANDCENTRIC_FAULT_WRITE_IN_PLACE_MS=<ms> set, files are
// written the naive way, in place: half the bytes, a pause of <ms>, then the rest.
bool write_in_place_if_faulty(const std::string& path, const std::string& bytes) {
  const char* pause = std::getenv("HANDCENTRIC_FAULT_WRITE_IN_PLACE_MS");
  if (pause == nullptr) return false;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  const std::size_t half = bytes.size() / 2;
  out.write(bytes.data(), static_cast<std::streamsize>(half));
  out.flush();
  std::this_thread::sleep_for(std::chrono::milliseconds(std::atoi(pause)));
  out.write(bytes.data() + half, static_cast<std::streamsize>(bytes.size() - half));
  if (!out.flush()) throw FileError("cannot write '" + path + "' (write failed)");
  return true;
}

}  // namespace

void write_file_atomically(const std::string& path, const std::string& bytes) {
  if (path.empty()) throw FileError("output path is empty; give a file name, e.g. out.jsonl");
  if (write_in_place_if_faulty(path, bytes)) return;
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
