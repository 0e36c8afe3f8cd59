// libFuzzer target: the demo file parser (sim::parse_demos, the reader behind load_demos).
// Any input must give demos or InvalidDemoFile; any other exception, a crash or a sanitizer
// report is a bug. Limits are the defaults, so the bounds users rely on are what is fuzzed.
#include <cstddef>
#include <cstdint>
#include <string>

#include "handcentric/sim/demos.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    const auto demos = handcentric::sim::parse_demos(bytes, "fuzz input");
    // What loads must be usable as training data: this is what `handcentric train` does next.
    if (!demos.empty()) (void)handcentric::sim::training_scenes(demos, 1, 2);
  } catch (const handcentric::sim::InvalidDemoFile&) {
  }
  return 0;
}
