#include "haarcast/net/http2_guard.h"

#include <chrono>

namespace haarcast::net {

bool RateBucket::take(double rate, double burst, Clock::time_point now) {
  if (tokens < 0) {
    tokens = burst;
  } else {
    const double seconds = std::chrono::duration<double>(now - at).count();
    tokens = std::min(burst, tokens + std::max(0.0, seconds) * rate);
  }
  at = now;
  if (tokens < 1) return false;
  tokens -= 1;
  return true;
}

// ------------------------------------------------------------------ Http2AddressRates

Http2AddressRates::Entry& Http2AddressRates::entry(const std::string& address, Clock::time_point now) {
  auto it = entries_.find(address);
  if (it == entries_.end()) {
    if (entries_.size() >= limits_.maxAddresses) {
      // Forget the least recently seen address that holds no connection
      // (its rates refill and its penalty lapses sooner or later anyway);
      // with every address connected, the table may grow by the
      // connections there are, which the per-address caps bound.
      auto oldest = entries_.end();
      for (auto e = entries_.begin(); e != entries_.end(); ++e) {
        if (e->second.connections == 0 && (oldest == entries_.end() || e->second.seen < oldest->second.seen)) oldest = e;
      }
      if (oldest != entries_.end()) entries_.erase(oldest);
    }
    it = entries_.emplace(address, Entry{}).first;
  }
  it->second.seen = now;
  return it->second;
}

void Http2AddressRates::connected(const std::string& address, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  ++entry(address, now).connections;
}

void Http2AddressRates::disconnected(const std::string& address) {
  std::lock_guard lock(mutex_);
  if (auto it = entries_.find(address); it != entries_.end() && it->second.connections > 0) --it->second.connections;
}

double Http2AddressRates::penaltyLeft(const std::string& address, Clock::time_point now) const {
  std::lock_guard lock(mutex_);
  const auto it = entries_.find(address);
  if (it == entries_.end() || it->second.penaltyUntil <= now) return 0;
  return std::chrono::duration<double>(it->second.penaltyUntil - now).count();
}

void Http2AddressRates::penalize(const std::string& address, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  entry(address, now).penaltyUntil =
      now + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(limits_.penaltySeconds));
}

bool Http2AddressRates::takeStream(const std::string& address, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  return entry(address, now).streams.take(limits_.addressStreamsPerSecond, limits_.addressStreamBurst, now);
}

bool Http2AddressRates::takeReset(const std::string& address, Clock::time_point now) {
  std::lock_guard lock(mutex_);
  return entry(address, now).resets.take(limits_.addressResetsPerSecond, limits_.addressResetBurst, now);
}

std::size_t Http2AddressRates::size() const {
  std::lock_guard lock(mutex_);
  return entries_.size();
}

// ------------------------------------------------------------------ Http2Guard

std::optional<Http2Abuse> Http2Guard::feed(std::span<const std::uint8_t> bytes, Clock::time_point now) {
  // The client's connection preface (RFC 9113 §3.4) comes first, whole.
  while (!prefaceDone() && !bytes.empty()) {
    if (static_cast<char>(bytes.front()) != http2::kPreface[prefaceHave_]) {
      return Http2Abuse{"not an HTTP/2 client: the connection preface is missing", "http2_preface", http2::kProtocolError};
    }
    ++prefaceHave_;
    bytes = bytes.subspan(1);
  }
  std::optional<Http2Abuse> abuse;
  reader_.read(bytes, [&](const Http2FrameHeader& h) {
    if (!abuse) abuse = onFrame(h, now);
  });
  return abuse;
}

std::optional<Http2Abuse> Http2Guard::onFrame(const Http2FrameHeader& h, Clock::time_point now) {
  const Http2Limits& l = rates_.limits();
  if (h.type == http2::kHeaders || (h.type == http2::kContinuation && inHeaderBlock_)) {
    headerBlockBytes_ = (h.type == http2::kHeaders ? 0 : headerBlockBytes_) + h.length;
    inHeaderBlock_ = (h.flags & http2::kEndHeaders) == 0;
    if (headerBlockBytes_ > l.maxHeaderBlockBytes) {
      return Http2Abuse{"a header block over " + std::to_string(l.maxHeaderBlockBytes) + " bytes (a CONTINUATION flood?)",
                        "http2_header_block"};
    }
  }
  if (h.type == http2::kHeaders && h.stream > lastStream_) {
    lastStream_ = h.stream;
    if (!streams_.take(l.streamsPerSecond, l.streamBurst, now)) {
      return Http2Abuse{"streams opened faster than " + std::to_string(static_cast<int>(l.streamsPerSecond)) +
                            " a second on one connection (after a burst of " +
                            std::to_string(static_cast<int>(l.streamBurst)) + ")",
                        "http2_stream_rate"};
    }
    if (!rates_.takeStream(address_, now)) {
      return Http2Abuse{"streams opened faster than " + std::to_string(static_cast<int>(l.addressStreamsPerSecond)) +
                            " a second from " + address_,
                        "http2_stream_rate"};
    }
  } else if (h.type == http2::kRstStream) {
    if (!resets_.take(l.resetsPerSecond, l.resetBurst, now)) {
      return Http2Abuse{"streams reset faster than " + std::to_string(static_cast<int>(l.resetsPerSecond)) +
                            " a second on one connection (after a burst of " +
                            std::to_string(static_cast<int>(l.resetBurst)) + "; HTTP/2 rapid reset?)",
                        "http2_reset_rate"};
    }
    if (!rates_.takeReset(address_, now)) {
      return Http2Abuse{"streams reset faster than " + std::to_string(static_cast<int>(l.addressResetsPerSecond)) +
                            " a second from " + address_ + " (HTTP/2 rapid reset?)",
                        "http2_reset_rate"};
    }
  }
  return std::nullopt;
}

std::string http2Goaway(std::uint32_t lastStream, std::uint32_t code, std::string_view debug) {
  const std::uint32_t length = static_cast<std::uint32_t>(8 + debug.size());
  std::string f;
  f.reserve(http2::kFrameHeaderBytes + length);
  auto put32 = [&f](std::uint32_t v) {
    for (int shift = 24; shift >= 0; shift -= 8) f.push_back(static_cast<char>((v >> shift) & 0xff));
  };
  f.push_back(static_cast<char>((length >> 16) & 0xff));
  f.push_back(static_cast<char>((length >> 8) & 0xff));
  f.push_back(static_cast<char>(length & 0xff));
  f.push_back(static_cast<char>(http2::kGoaway));
  f.push_back(0);  // no flags
  put32(0);        // stream 0: the connection
  put32(lastStream & 0x7fffffffu);
  put32(code);
  f.append(debug);
  return f;
}

}  // namespace haarcast::net
