// The WebSocket upgrade: the checks an upgrade request passes before any
// session state exists (path, Origin, token and the address's guess limit),
// the HTTP parser's limits, and the settings of a session's WebSocket stream.
// http_session.cpp and ws_session.cpp use them on TCP sockets; the
// WebSocket fuzz target (tests/fuzz/fuzz_websocket.cpp) uses the same ones
// over a Beast test stream, so what is fuzzed is what is served.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include "haarcast/net/access.h"
#include "haarcast/net/host_check.h"
#include "haarcast/net/server.h"

namespace haarcast::net {

using HttpRequest = boost::beast::http::request<boost::beast::http::string_body>;

// HTTP requests are small: a GET and its headers.
inline constexpr std::uint32_t kMaxHttpHeaderBytes = 16 * 1024;
inline constexpr std::uint64_t kMaxHttpBodyBytes = 16 * 1024;

void limitRequestParser(boost::beast::http::request_parser<boost::beast::http::string_body>& parser);

// Why an upgrade request is refused, as the response says it.
struct UpgradeRefusal {
  boost::beast::http::status status = boost::beast::http::status::forbidden;
  std::string body;        // one line naming the problem and the way out
  std::string metric;      // the /metrics refusal reason; "" for a 404 (nothing is at that path)
  std::string logLine;     // "" when the refusal is not worth a log line
  std::string retryAfter;  // the Retry-After header's seconds, or ""
  bool bearerChallenge = false;  // WWW-Authenticate: Bearer (a 401)
};

// The Host rule (hostAllowed against options.allowHosts) as a refusal: 421
// Misdirected Request naming the host and --allow-host, or nullopt.
std::optional<UpgradeRefusal> checkHost(const HttpRequest& request, const ServerOptions& options,
                                        const std::string& address);

// The framing rule of RFC 9112 §6.1: a request whose Transfer-Encoding is
// anything but exactly "chunked" (the one coding this server decodes: not
// "xchunked", not "chunked, identity", not "gzip, chunked") gets 400, since
// where its body ends is not known. "" when the request is fine, else why.
std::string badTransferCoding(const HttpRequest& request);

// The checks in order: the path (/ws), the Host (checkHost), the Origin (originAllowed against the
// Host and options.allowOrigins), then, when the server has a token, the
// address's guess limit and the token (`?token=T` or `Authorization: Bearer
// T`). A wrong token counts toward `guard`'s limits (the address's and the
// server's); a missing one does not (it is not a guess); the right one makes
// `address` a known client, which a server-wide lock lets through.
// nullopt: the request may go on to the draining and slot checks, which
// need the server's state.
std::optional<UpgradeRefusal> checkUpgrade(const HttpRequest& request, const ServerOptions& options,
                                           TokenGuard& guard, const std::string& address, Clock::time_point now);

// A session's WebSocket: the handshake within options.handshakeSeconds, no
// idle timeout or pings of Beast's own (the session's idle rule sends an
// Error TIMEOUT with a reason), binary messages, the Server header, and a
// read limit that is a backstop only: messages over limits.maxMessageBytes
// get Error MESSAGE_TOO_LARGE from the session; far larger ones are cut here
// (close code 1009) before they are buffered.
template <class NextLayer>
void configureSessionStream(boost::beast::websocket::stream<NextLayer>& ws, const ServerOptions& options) {
  namespace websocket = boost::beast::websocket;
  websocket::stream_base::timeout timeouts{};
  timeouts.handshake_timeout = toDuration(options.handshakeSeconds);
  timeouts.idle_timeout = websocket::stream_base::none();
  timeouts.keep_alive_pings = false;
  ws.set_option(timeouts);
  ws.set_option(websocket::stream_base::decorator([](websocket::response_type& res) {
    res.set(boost::beast::http::field::server, kServerVersion);
  }));
  ws.read_message_max(options.limits.maxMessageBytes * 4 + 4096);
  ws.binary(true);
}

}  // namespace haarcast::net
