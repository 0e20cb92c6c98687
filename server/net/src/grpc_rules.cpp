#include "haarcast/net/grpc_rules.h"

#include "haarcast/net/messages.h"

namespace haarcast::net {

GrpcCode grpcCodeFor(v1::ErrorCode code) {
  switch (code) {
    case v1::ERROR_CODE_UNAUTHORIZED: return GrpcCode::Unauthenticated;
    case v1::ERROR_CODE_BAD_MESSAGE:
    case v1::ERROR_CODE_UNSUPPORTED_VERSION:
    case v1::ERROR_CODE_BAD_RESOLUTION:
    case v1::ERROR_CODE_BAD_SETTINGS:
    case v1::ERROR_CODE_UNKNOWN_SCENE:
    case v1::ERROR_CODE_UNKNOWN_MATERIAL: return GrpcCode::InvalidArgument;
    case v1::ERROR_CODE_PROTOCOL_ORDER: return GrpcCode::FailedPrecondition;
    case v1::ERROR_CODE_MESSAGE_TOO_LARGE:
    case v1::ERROR_CODE_TOO_MANY_SESSIONS:
    case v1::ERROR_CODE_OVERLOADED: return GrpcCode::ResourceExhausted;
    case v1::ERROR_CODE_TIMEOUT: return GrpcCode::DeadlineExceeded;
    case v1::ERROR_CODE_SHUTTING_DOWN: return GrpcCode::Unavailable;
    case v1::ERROR_CODE_RENDER_FAILED:
    case v1::ERROR_CODE_UNSPECIFIED:
    default: return GrpcCode::Internal;
  }
}

std::string grpcPeerGroup(std::string_view peer) {
  std::string_view host;
  if (peer.starts_with("ipv4:")) {
    host = peer.substr(5);
    host = host.substr(0, host.rfind(':'));
  } else if (peer.starts_with("ipv6:")) {
    std::string_view rest = peer.substr(5);
    std::string_view open = "[", close = "]";
    if (rest.starts_with("%5B") || rest.starts_with("%5b")) {
      open = rest.substr(0, 3);
      close = "%5D";
    }
    if (!rest.starts_with(open)) return std::string(peer);
    rest.remove_prefix(open.size());
    auto end = rest.find(close);
    if (end == std::string_view::npos && close == "%5D") end = rest.find("%5d");
    if (end == std::string_view::npos) return std::string(peer);
    host = rest.substr(0, end);
  } else {
    return std::string(peer);  // unix sockets and the like: their own group
  }
  return clientGroup(host);
}

std::optional<GrpcRefusal> checkGrpcToken(std::string_view authorization, const std::string& serverToken,
                                          TokenGuard& guard, const std::string& address, Clock::time_point now) {
  if (serverToken.empty()) return std::nullopt;
  // As the upgrade (upgrade.cpp checkUpgrade): which lock holds, by its own
  // label; the right token recorded, so that a known client passes a
  // server-wide lock that a spray from many addresses has set.
  if (const auto lock = guard.check(address, now); lock != TokenGuard::Lock::None) {
    const bool server = lock == TokenGuard::Lock::Server;
    return GrpcRefusal{GrpcCode::ResourceExhausted,
                       server ? "too many wrong tokens on this server from many addresses: try again later"
                              : "too many wrong tokens from " + address + ": try again later",
                       server ? "token_rate_server" : "token_rate"};
  }
  const std::string given = bearerToken(authorization);
  if (tokensEqual(given, serverToken)) {
    guard.succeeded(address, now);
    return std::nullopt;
  }
  if (!given.empty()) guard.failed(address, now);  // a guess; no token is not one
  return GrpcRefusal{GrpcCode::Unauthenticated,
                     given.empty() ? "no token: send the metadata `authorization: Bearer <token>`" : "wrong token",
                     "token"};
}

}  // namespace haarcast::net
