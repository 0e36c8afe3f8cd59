// libFuzzer target: the readers of recorded observations (props/observation/recorded.hpp), from
// memory. The first byte picks the reader: 0 the rest as an .npz file (libzip, then the .npy
// parser and the observations' validation), 1 as JSON Lines, 2 and 3 the rest as .npy members
// (split at "\nNPY\n", named history, extra_poses/goal, scalars/gripper, held/ids in turn) of a
// zip this target writes, stored (2) or deflated (3), so that mutations reach the .npy parser
// behind the CRC. Any input must load or give handcentric::Error.
#include <zip.h>

#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <string_view>

#include "handcentric/core/errors.hpp"
#include "handcentric/props/observation/recorded.hpp"
#include "observation/npz.hpp"

namespace {

// The members as a zip archive in memory, or "" where libzip refuses (not what is fuzzed).
std::string zip_of(std::string_view rest, bool deflate) {
  static const char* const names[] = {"history.npy", "extra_poses/goal.npy", "scalars/gripper.npy",
                                      "held/ids.npy"};
  zip_source_t* buffer = zip_source_buffer_create(nullptr, 0, 0, nullptr);
  if (buffer == nullptr) return "";
  zip_t* archive = zip_open_from_source(buffer, ZIP_TRUNCATE, nullptr);
  if (archive == nullptr) {
    zip_source_free(buffer);
    return "";
  }
  zip_source_keep(buffer);
  bool ok = true;
  for (std::size_t i = 0; ok && i < 4; ++i) {
    const std::size_t end = rest.find("\nNPY\n");
    const std::string_view npy = rest.substr(0, end);
    rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 5);
    zip_source_t* member = zip_source_buffer(archive, npy.data(), npy.size(), 0);
    const zip_int64_t index =
        member == nullptr ? -1 : zip_file_add(archive, names[i], member, ZIP_FL_ENC_UTF_8);
    if (index < 0) {
      zip_source_free(member);
      ok = false;
    } else {
      ok = zip_set_file_compression(archive, static_cast<zip_uint64_t>(index),
                                    deflate ? ZIP_CM_DEFLATE : ZIP_CM_STORE, 0) == 0;
    }
    if (end == std::string_view::npos) break;
  }
  std::string out;
  if (!ok || zip_close(archive) != 0) {
    zip_discard(archive);
  } else if (zip_source_open(buffer) == 0) {
    char chunk[4096];
    for (zip_int64_t n; (n = zip_source_read(buffer, chunk, sizeof chunk)) > 0;)
      out.append(chunk, static_cast<std::size_t>(n));
    zip_source_close(buffer);
  }
  zip_source_free(buffer);
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view rest(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    switch (data[0] & 3) {
      case 0:
        (void)handcentric::props::observations_from_npz(rest, "fuzz.npz");
        break;
      case 1: {
        std::istringstream lines{std::string(rest)};
        (void)handcentric::props::observations_from_json_lines(lines, "fuzz.jsonl");
        break;
      }
      default: {
        const std::string zip = zip_of(rest, (data[0] & 3) == 3);
        if (!zip.empty()) (void)handcentric::props::observations_from_npz(zip, "fuzz.npz");
      }
    }
  } catch (const handcentric::Error&) {
  }
  return 0;
}
