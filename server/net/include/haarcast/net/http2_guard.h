// What the server checks in a gRPC client's HTTP/2 bytes before gRPC sees
// them (the gRPC port's front, grpc_front.h). Debian 12's gRPC 1.51 predates
// the HTTP/2 rapid-reset mitigations (CVE-2023-44487): a client that opens
// streams and resets them at once is never refused, and each stream costs a
// call, a reactor and a session. The front reads only the 9-byte frame
// headers (RFC 9113 §4.1), never HPACK or payloads, and counts per connection
// and per client address:
//   streams opened   a HEADERS frame on a stream id above every earlier one;
//   resets           RST_STREAM frames from the client;
//   header blocks    HEADERS + CONTINUATION bytes of one block (a
//                    CONTINUATION flood never ends its block).
// Past a limit the connection gets GOAWAY (ENHANCE_YOUR_CALM) and is closed,
// and its address is refused new gRPC connections for a while. Plain classes
// over bytes and clocks, tested without sockets.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "haarcast/net/token_guard.h"  // Clock

namespace haarcast::net {

// RFC 9113 §6: the frame types and flags the guard reads, and §7's codes.
namespace http2 {
inline constexpr std::string_view kPreface = "PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n";
inline constexpr std::size_t kFrameHeaderBytes = 9;
inline constexpr std::uint8_t kHeaders = 0x1, kRstStream = 0x3, kGoaway = 0x7, kContinuation = 0x9;
inline constexpr std::uint8_t kEndHeaders = 0x4;
inline constexpr std::uint32_t kProtocolError = 0x1, kEnhanceYourCalm = 0xb;
}  // namespace http2

struct Http2FrameHeader {
  std::uint32_t length = 0;
  std::uint8_t type = 0;
  std::uint8_t flags = 0;
  std::uint32_t stream = 0;
};

// Splits a byte stream of HTTP/2 frames (after any preface) into frame
// headers, fed in pieces of any size; payloads are skipped, not kept.
class Http2FrameReader {
 public:
  // Reads up to `bytes.size()` bytes, calling onFrame for each frame header
  // completed. With `stopAtBoundary`, stops at the first frame boundary (at
  // once when already at one). Returns the bytes read.
  template <typename OnFrame>
  std::size_t read(std::span<const std::uint8_t> bytes, OnFrame&& onFrame, bool stopAtBoundary = false);
  // True between frames: no header or payload half read.
  bool atBoundary() const { return headerHave_ == 0 && payloadLeft_ == 0; }

 private:
  std::uint8_t header_[http2::kFrameHeaderBytes] = {};
  std::size_t headerHave_ = 0;
  std::uint64_t payloadLeft_ = 0;
};

// A token bucket: `burst` events at once, then `rate` a second.
struct RateBucket {
  double tokens = -1;  // < 0: full (not yet used)
  Clock::time_point at{};
  bool take(double rate, double burst, Clock::time_point now);
};

struct Http2Limits {
  // One connection.
  double streamsPerSecond = 16;
  double streamBurst = 64;
  double resetsPerSecond = 4;
  double resetBurst = 32;
  std::size_t maxHeaderBlockBytes = 64 * 1024;
  // One client address, all its connections together.
  double addressStreamsPerSecond = 64;
  double addressStreamBurst = 256;
  double addressResetsPerSecond = 16;
  double addressResetBurst = 128;
  // After a connection is cut for abuse, its address's new gRPC
  // connections are refused this long.
  double penaltySeconds = 10;
  // Addresses remembered (rates and penalties); past it the least recently
  // seen address without a connection is forgotten.
  std::size_t maxAddresses = 4096;
};

// Why a connection is cut.
struct Http2Abuse {
  std::string reason;     // for the log and GOAWAY's debug data
  std::string label;      // haarcast_refusals_total{reason}
  std::uint32_t code = http2::kEnhanceYourCalm;  // GOAWAY's error code
};

// The per-address half: rates shared by an address's connections, its
// penalty, and how many connections it holds. Thread-safe.
class Http2AddressRates {
 public:
  explicit Http2AddressRates(Http2Limits limits) : limits_(limits) {}
  const Http2Limits& limits() const { return limits_; }

  // A connection from `address` opens or closes.
  void connected(const std::string& address, Clock::time_point now);
  void disconnected(const std::string& address);
  // Seconds of penalty left for `address` (0: none).
  double penaltyLeft(const std::string& address, Clock::time_point now) const;
  void penalize(const std::string& address, Clock::time_point now);
  bool takeStream(const std::string& address, Clock::time_point now);
  bool takeReset(const std::string& address, Clock::time_point now);
  std::size_t size() const;

 private:
  struct Entry {
    int connections = 0;
    RateBucket streams, resets;
    Clock::time_point penaltyUntil{}, seen{};
  };
  Entry& entry(const std::string& address, Clock::time_point now);  // under mutex_
  Http2Limits limits_;
  mutable std::mutex mutex_;
  std::map<std::string, Entry> entries_;
};

// One connection's client-to-server bytes, checked as they pass.
class Http2Guard {
 public:
  // `rates` is shared by the server's connections and outlives the guard.
  Http2Guard(Http2AddressRates& rates, std::string address) : rates_(rates), address_(std::move(address)) {}

  // The next bytes from the client: nullopt while they may pass to gRPC;
  // otherwise why the connection is cut (nothing of these bytes passes).
  std::optional<Http2Abuse> feed(std::span<const std::uint8_t> bytes, Clock::time_point now);
  // The highest stream the client opened: GOAWAY's last stream id.
  std::uint32_t lastStream() const { return lastStream_; }
  bool prefaceDone() const { return prefaceHave_ == http2::kPreface.size(); }

 private:
  std::optional<Http2Abuse> onFrame(const Http2FrameHeader& h, Clock::time_point now);

  Http2AddressRates& rates_;
  std::string address_;
  std::size_t prefaceHave_ = 0;
  Http2FrameReader reader_;
  RateBucket streams_, resets_;
  std::uint32_t lastStream_ = 0;
  bool inHeaderBlock_ = false;
  std::uint64_t headerBlockBytes_ = 0;
};

// A GOAWAY frame (RFC 9113 §6.8) with `debug` as its opaque data.
std::string http2Goaway(std::uint32_t lastStream, std::uint32_t code, std::string_view debug);

// ------------------------------------------------------------------ template

template <typename OnFrame>
std::size_t Http2FrameReader::read(std::span<const std::uint8_t> bytes, OnFrame&& onFrame, bool stopAtBoundary) {
  std::size_t at = 0;
  while (at < bytes.size()) {
    if (stopAtBoundary && atBoundary()) break;
    if (payloadLeft_ > 0) {
      const std::size_t skip = static_cast<std::size_t>(std::min<std::uint64_t>(payloadLeft_, bytes.size() - at));
      payloadLeft_ -= skip;
      at += skip;
      continue;
    }
    header_[headerHave_++] = bytes[at++];
    if (headerHave_ < http2::kFrameHeaderBytes) continue;
    headerHave_ = 0;
    Http2FrameHeader h;
    h.length = (std::uint32_t{header_[0]} << 16) | (std::uint32_t{header_[1]} << 8) | header_[2];
    h.type = header_[3];
    h.flags = header_[4];
    h.stream = ((std::uint32_t{header_[5]} << 24) | (std::uint32_t{header_[6]} << 16) |
                (std::uint32_t{header_[7]} << 8) | header_[8]) & 0x7fffffffu;
    payloadLeft_ = h.length;
    onFrame(h);
  }
  return at;
}

}  // namespace haarcast::net
