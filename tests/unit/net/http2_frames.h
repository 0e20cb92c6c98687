// HTTP/2 frames written by hand for the gRPC front's tests: a 9-byte frame
// header (RFC 9113 §4.1).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace haarcast::net::test {

inline std::string http2FrameHeader(std::size_t length, std::uint8_t type, std::uint8_t flags, std::uint32_t stream) {
  std::string f;
  f.push_back(static_cast<char>((length >> 16) & 0xff));
  f.push_back(static_cast<char>((length >> 8) & 0xff));
  f.push_back(static_cast<char>(length & 0xff));
  f.push_back(static_cast<char>(type));
  f.push_back(static_cast<char>(flags));
  for (int shift = 24; shift >= 0; shift -= 8) f.push_back(static_cast<char>((stream >> shift) & 0xff));
  return f;
}

}  // namespace haarcast::net::test
