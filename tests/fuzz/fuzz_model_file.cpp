// libFuzzer target: the model file parser (policy::deserialize_model, the reader behind
// load_model). Any input must give a policy or InvalidModelFile (InvalidArgument is for sampling
// overrides out of range, and none are given here).
//
// A model file ends with a checksum of everything before it, so almost every mutation would
// stop at the checksum test. When the first byte is odd, the target rewrites the last 8 bytes
// as the right checksum (of the rest, without that byte), which sends the mutations into the
// config, header and weight readers behind it; an even first byte fuzzes the bytes as they are.
#include <cstddef>
#include <cstdint>
#include <string>

#include "handcentric/policy/binary_io.hpp"
#include "handcentric/policy/errors.hpp"
#include "handcentric/policy/model_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  if ((data[0] & 1) != 0 && bytes.size() >= 8) {
    std::uint64_t checksum = handcentric::policy::fnv1a64(bytes.data(), bytes.size() - 8);
    for (std::size_t i = 0; i < 8; ++i, checksum >>= 8) {
      bytes[bytes.size() - 8 + i] = static_cast<char>(checksum & 0xff);
    }
  }
  try {
    (void)handcentric::policy::deserialize_model(bytes, "fuzz input");
  } catch (const handcentric::InvalidModelFile&) {
  }
  return 0;
}
