#include "handcentric/core/atomic_file.hpp"

#include <fcntl.h>
#include <signal.h>
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

// "<path>.tmp.<pid>": unique per writing process, so two processes writing the same path never
// share a temporary file.
std::string temporary_name(const std::string& path, pid_t pid) {
  return path + ".tmp." + std::to_string(pid);
}

// A writer killed between creating its temporary file and the rename leaves "<path>.tmp.<pid>"
// behind. The next write of the same path removes those whose process is gone (kill(pid, 0)
// fails with ESRCH); a live writer's temporary file is left alone.
void remove_stale_temporaries(const std::string& path) {
  const std::filesystem::path target(path);
  const std::string prefix = target.filename().string() + ".tmp.";
  const std::filesystem::path folder =
      target.has_parent_path() ? target.parent_path() : std::filesystem::path(".");
  std::error_code error;
  std::filesystem::directory_iterator entries(folder, error);
  if (error) return;  // the write itself reports a missing or unreadable folder
  for (const auto& entry : entries) {
    const std::string name = entry.path().filename().string();
    if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string digits = name.substr(prefix.size());
    if (digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) continue;
    const pid_t pid = static_cast<pid_t>(std::stol(digits));
    if (pid <= 0 || pid == ::getpid()) continue;
    if (::kill(pid, 0) != 0 && errno == ESRCH) std::filesystem::remove(entry.path(), error);
  }
}

bool write_all(int fd, const std::string& bytes) {
  std::size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    written += static_cast<std::size_t>(n);
  }
  return true;
}

// The rename is durable once the folder's entry is on disk. Best effort: some file systems
// refuse fsync on a directory, and the file is complete either way.
void sync_directory_of(const std::string& path) {
  const std::filesystem::path target(path);
  const std::string folder = target.has_parent_path() ? target.parent_path().string() : ".";
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;
  ::fsync(fd);
  ::close(fd);
}

}  // namespace

void write_file_atomically(const std::string& path, const std::string& bytes) {
  if (path.empty()) throw FileError("output path is empty; give a file name, e.g. out.jsonl");
  if (write_in_place_if_faulty(path, bytes)) return;
  remove_stale_temporaries(path);
  const std::string temporary = temporary_name(path, ::getpid());
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    throw FileError("cannot write '" + path + "' (" + std::strerror(errno) +
                    "); check that its directory exists and is writable");
  }
  // fsync before the rename: otherwise a power cut after it can leave the new name on an empty
  // or partial file (the rename reaches the disk before the data on some file systems).
  if (!write_all(fd, bytes) || ::fsync(fd) != 0) {
    const std::string reason = std::strerror(errno);
    ::close(fd);
    std::remove(temporary.c_str());
    throw FileError("cannot write '" + path + "' (" + reason + "); check the free space");
  }
  ::close(fd);
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::remove(temporary.c_str());
    throw FileError("cannot write '" + path + "' (" + error.message() +
                    "); check that it is not a directory and that its folder is writable");
  }
  sync_directory_of(path);
}

}  // namespace handcentric
