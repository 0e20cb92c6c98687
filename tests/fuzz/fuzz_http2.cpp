// libFuzzer target: the gRPC port's HTTP/2 guard (http2_guard.h) on
// arbitrary client bytes. Byte 0 picks the piece size (1–256) the rest is
// fed in; the same bytes fed whole must give the same verdict (cut or not,
// and why) and the same last stream, since the guard reads frame headers
// whatever the reads' sizes (one instant for both: the rates are not what
// is fuzzed here, the unit tests hold them).
#include <cstddef>
#include <cstdint>
#include <span>

#include "haarcast/net/http2_guard.h"

using haarcast::net::Clock;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::size_t piece = std::size_t{data[0]} + 1;
  const std::span<const std::uint8_t> bytes(data + 1, size - 1);
  const auto t0 = Clock::time_point{} + std::chrono::hours(1);

  haarcast::net::Http2AddressRates wholeRates({}), splitRates({});
  haarcast::net::Http2Guard whole(wholeRates, "10.0.0.1"), split(splitRates, "10.0.0.1");
  const auto wholeVerdict = whole.feed(bytes, t0);
  std::optional<haarcast::net::Http2Abuse> splitVerdict;
  for (std::size_t at = 0; at < bytes.size() && !splitVerdict; at += piece) {
    splitVerdict = split.feed(bytes.subspan(at, std::min(piece, bytes.size() - at)), t0);
  }
  // Cut at the same frame for the same reason, or passed both ways.
  if (splitVerdict.has_value() != wholeVerdict.has_value()) __builtin_trap();
  if (splitVerdict && splitVerdict->label != wholeVerdict->label) __builtin_trap();
  if (split.lastStream() != whole.lastStream()) __builtin_trap();
  // The GOAWAY the front would send is a well-formed frame.
  const std::string goaway = haarcast::net::http2Goaway(whole.lastStream(), haarcast::net::http2::kEnhanceYourCalm,
                                                        wholeVerdict ? wholeVerdict->reason : "");
  const std::size_t length = (std::size_t{static_cast<std::uint8_t>(goaway[0])} << 16) |
                             (std::size_t{static_cast<std::uint8_t>(goaway[1])} << 8) |
                             static_cast<std::uint8_t>(goaway[2]);
  if (goaway.size() != 9 + length || length < 8) __builtin_trap();
  return 0;
}
