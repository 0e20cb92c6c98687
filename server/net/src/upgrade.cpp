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
  if (guard.locked(address, now)) {
    UpgradeRefusal r;
    r.status = http::status::too_many_requests;
    r.body = "too many wrong tokens from " + address + ": try again later\n";
    r.metric = "token_rate";
    r.retryAfter = std::to_string(static_cast<int>(options.tokenGuard.lockoutSeconds));
    return r;
  }
  std::string given = queryParameter(target, "token");
  if (given.empty()) given = bearerToken(view(request[http::field::authorization]));
  if (tokensEqual(given, options.token)) return std::nullopt;
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
