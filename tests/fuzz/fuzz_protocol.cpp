// libFuzzer target: the wire protocol without a socket. Each input is a
// sequence of client messages, each after a 2-byte little-endian header: the
// low 15 bits are its length, the top bit says it came as a text message.
// Every message goes to a RenderSession (render_session.h) as ws_session.cpp
// hands it one: decode, validate, then Hello / settings / scene / pose /
// ping applied, with builds and frames completed at once (fuzz_session.h).
// A refused message is an Error the session sends; an exception, a crash, a
// sanitizer report or a broken port contract (fuzz_session.h) is a finding.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "fuzz_session.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  haarcast::net::fuzz::FuzzSession session;
  std::size_t at = 0;
  while (size - at >= 2 && !session.closed()) {
    const std::size_t header = data[at] | (static_cast<std::size_t>(data[at + 1]) << 8);
    at += 2;
    const std::size_t length = header & 0x7FFF;
    const bool text = (header & 0x8000) != 0;
    const std::size_t take = length < size - at ? length : size - at;
    session.receive(std::string_view(reinterpret_cast<const char*>(data + at), take), !text);
    at += take;
  }
  return 0;
}
