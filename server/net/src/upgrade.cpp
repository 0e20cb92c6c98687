#include "haarcast/net/upgrade.h"

#include "haarcast/net/messages.h"
#include "haarcast/net/static_files.h"

namespace haarcast::net {
namespace {

namespace http = boost::beast::http;

std::string_view view(boost::beast::string_view s) { return {s.data(), s.size()}; }

}  // namespace

void limitRequestParser(http::request_parser<http::string_body>& parser) {
  parser.header_limit(kMaxHttpHeaderBytes);
  parser.body_limit(kMaxHttpBodyBytes);
}

std::optional<UpgradeRefusal> checkHost(const HttpRequest& request, const ServerOptions& options,
                                        const std::string& address) {
  // RFC 9112 §3.2: an HTTP/1.1 request has exactly one Host field. With two,
  // which one names the server is a guess (a proxy and this server may
  // guess differently); without one (HTTP/1.1), the name check below would
  // have nothing to check. HTTP/1.0 may omit it.
  std::size_t hosts = 0;
  for (const auto& field : request.base()) hosts += field.name() == http::field::host ? 1 : 0;
  if (hosts > 1 || (hosts == 0 && request.version() >= 11)) {
    UpgradeRefusal r;
    r.status = http::status::bad_request;
    r.body = hosts > 1 ? "bad request: " + std::to_string(hosts) + " Host header fields (HTTP/1.1 takes exactly one)\n"
                       : std::string("bad request: no Host header field (HTTP/1.1 requires one)\n");
    r.metric = "host";
    r.logLine = "request from " + address + " refused: " + std::to_string(hosts) + " Host header fields";
    return r;
  }
  const std::string_view host = view(request[http::field::host]);
  if (hostAllowed(host, options.allowHosts)) return std::nullopt;
  UpgradeRefusal r;
  r.status = http::status::misdirected_request;
  r.body = misdirectedBody(host);
  r.metric = "host";
  r.logLine = "request from " + address + " refused: Host \"" + sanitizeForLog(host) + "\" is not --allow-host";
  return r;
}

std::string badTransferCoding(const HttpRequest& request) {
  // Every Transfer-Encoding field, joined as one list (RFC 9110 §5.3).
  std::string codings;
  bool present = false;
  for (const auto& field : request.base()) {
    if (field.name() != http::field::transfer_encoding) continue;
    present = true;
    if (!codings.empty()) codings += ", ";
    codings += std::string(view(field.value()));
  }
  if (!present) return "";
  std::string_view s = codings;
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  if (boost::beast::iequals(boost::beast::string_view(s.data(), s.size()), "chunked")) return "";
  return "bad request: Transfer-Encoding \"" + sanitizeForLog(codings) +
         "\" is not supported (only \"chunked\" alone)\n";
}

std::optional<UpgradeRefusal> checkUpgrade(const HttpRequest& request, const ServerOptions& options,
                                           TokenGuard& guard, const std::string& address, Clock::time_point now) {
  const std::string_view target = view(request.target());
  const std::string_view path = targetPath(target);
  if (path != "/ws") {
    UpgradeRefusal r;
    r.status = http::status::not_found;
    r.body = "no WebSocket at " + sanitizeForLog(path, 256) + " (use /ws)\n";
    return r;
  }
  // Before the Origin: a rebound name sends a matching Origin and Host.
  if (auto r = checkHost(request, options, address)) return r;
  // A page on another site must not drive the server with the user's
  // network position (cross-site WebSocket hijacking).
  if (const auto origin = view(request[http::field::origin]);
      !originAllowed(origin, view(request[http::field::host]), options.allowOrigins)) {
    UpgradeRefusal r;
    r.status = http::status::forbidden;
    r.body = "forbidden: Origin " + sanitizeForLog(origin) + " may not open a session (see --allow-origin)\n";
    r.metric = "origin";
    r.logLine = "upgrade from " + address + " refused: Origin \"" + sanitizeForLog(origin) +
                "\" is neither this host nor --allow-origin";
    return r;
  }
  if (options.token.empty()) return std::nullopt;
  if (const auto lock = guard.check(address, now); lock != TokenGuard::Lock::None) {
    const bool server = lock == TokenGuard::Lock::Server;
    UpgradeRefusal r;
    r.status = http::status::too_many_requests;
    r.body = server ? "too many wrong tokens on this server from many addresses: try again later\n"
                    : "too many wrong tokens from " + address + ": try again later\n";
    r.metric = server ? "token_rate_server" : "token_rate";
    r.logLine = "upgrade from " + address + " refused: " +
                (server ? "the server-wide wrong-token limit is in force" : "the address's wrong-token limit is in force");
    r.retryAfter = std::to_string(static_cast<int>(options.tokenGuard.lockoutSeconds));
    return r;
  }
  std::string given = queryParameter(target, "token");
  if (given.empty()) given = bearerToken(view(request[http::field::authorization]));
  if (tokensEqual(given, options.token)) {
    guard.succeeded(address, now);  // a known client: it passes a server-wide lock
    return std::nullopt;
  }
  if (!given.empty()) guard.failed(address, now);  // a guess; no token is not one
  UpgradeRefusal r;
  r.status = http::status::unauthorized;
  r.body = given.empty() ? "unauthorized: no token (use ?token=T or Authorization: Bearer T)\n"
                         : "unauthorized: wrong token\n";
  r.metric = "token";
  r.logLine = "upgrade from " + address + " refused: " + (given.empty() ? "no" : "wrong") + " token";
  r.bearerChallenge = true;
  return r;
}

}  // namespace haarcast::net
