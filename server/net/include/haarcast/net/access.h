// Who may connect and how much they may hold: the Origin check at the
// WebSocket upgrade, the token's Authorization scheme (the guess limits are
// in token_guard.h; the slots in admission.h), the client groups that
// per-address limits count, and the accept loop's back-off when file
// descriptors run out. Plain classes over strings and clocks, tested without sockets.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <array>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "haarcast/net/admission.h"
#include "haarcast/net/token_guard.h"

namespace haarcast::net {

// Seconds → a Clock duration (negative: 0).
inline std::chrono::nanoseconds toDuration(double seconds) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(std::max(0.0, seconds)));
}

// The Origin rule (RFC 6454; as gorilla/websocket's checkSameOrigin and
// Selkies do): no Origin header is a non-browser client and is allowed; an
// Origin whose host[:port] equals the request's Host (case-insensitive) is
// the page the server itself served; otherwise the Origin must be on the
// operator's allow-list ("https://app.example.com", compared without case
// and without a trailing '/'). Everything else — "null" included — is a
// page on another site (cross-site WebSocket hijacking) and gets 403.
bool originAllowed(std::string_view origin, std::string_view host, const std::vector<std::string>& allowList);

// The token of an `Authorization: Bearer T` header; the scheme is
// case-insensitive (RFC 7235 §2.1). "" when the header is another scheme.
std::string bearerToken(std::string_view authorization);

// Equal-time comparison: the token check does not leak how much matched.
bool tokensEqual(std::string_view given, std::string_view expected);

// True for 127.0.0.0/8, ::1 and an IPv4-mapped loopback; false for anything
// else, "0.0.0.0" and "::" included (they listen on every interface).
bool isLoopbackAddress(std::string_view address);

// The key of per-address limits for a peer address: an IPv4 address (an
// IPv4-mapped IPv6 one as IPv4), IPv6 loopback as itself, and any other
// IPv6 address as its /64 ("2001:db8:1:2::/64"), since one host may pick
// any address in its /64. Anything unparsable is its own key.
std::string clientGroup(std::string_view address);

// The accept loop's pause after an error: EMFILE, ENFILE, ENOBUFS and
// ENOMEM mean a retry at once fails again (a busy loop that floods the log),
// so the pause doubles from 50 ms to 1 s; other errors retry at once. One
// log line per episode: `onError` says whether this error started one.
class AcceptBackoff {
 public:
  static constexpr std::chrono::milliseconds kFirst{50};
  static constexpr std::chrono::milliseconds kMost{1000};

  struct Step {
    std::chrono::milliseconds pause{0};
    bool episodeStarted = false;  // the first resource error since the last good accept: log it
  };
  Step onError(int errnoValue);  // the failed accept's errno (0: not a system error)
  // A good accept; returns true when it ended an episode (log the recovery).
  bool onSuccess();
  int errorsInEpisode() const { return errors_; }

 private:
  std::chrono::milliseconds pause_{0};
  int errors_ = 0;
};

}  // namespace haarcast::net
