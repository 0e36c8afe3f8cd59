// libFuzzer target: the --exec plug-in reply parser (props::parse_reply), for every kind of
// request (encode, flow, decode, policy) and with and without a hello allowed (the handshake
// that selects the protocol version). The first byte picks the request; the rest is the line.
// Any line must parse or give PluginError.
#include <cstddef>
#include <cstdint>
#include <string>

#include "handcentric/props/transport/plugin_protocol.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  using handcentric::props::RequestKind;
  constexpr RequestKind kinds[] = {RequestKind::encode, RequestKind::flow, RequestKind::decode,
                                   RequestKind::policy};
  const RequestKind kind = kinds[data[0] & 3];
  const bool hello_allowed = (data[0] & 4) != 0;
  const std::string line(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    (void)handcentric::props::parse_reply(line, 1, kind, "fuzz plug-in", hello_allowed);
  } catch (const handcentric::props::PluginError&) {
  }
  return 0;
}
