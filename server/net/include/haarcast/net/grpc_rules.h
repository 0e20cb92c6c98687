// The gRPC transport's rules, apart from gRPC itself so that they are tested
// without a channel: which status ends a stream whose session failed, which
// client address a gRPC peer string names, and the token check a stream
// meets before its first message (the WebSocket upgrade's, in metadata).
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "haarcast/net/access.h"
#include "haarcast/proto/haarcast.pb.h"

namespace haarcast::net {

// grpc::StatusCode's values (they are the wire's, fixed by the gRPC spec),
// named here so that this header needs no gRPC.
enum class GrpcCode : int {
  Ok = 0,
  Cancelled = 1,
  InvalidArgument = 3,
  DeadlineExceeded = 4,
  ResourceExhausted = 8,
  FailedPrecondition = 9,
  Internal = 13,
  Unavailable = 14,
  Unauthenticated = 16,
};

// The status that ends a stream after a fatal Error with this code: the
// Error is the stream's last message, and the status says the same to a
// client that only looks at statuses (retry policies, grpcurl, probes).
GrpcCode grpcCodeFor(v1::ErrorCode code);

// The client group (clientGroup(), access.h) of a gRPC peer string:
// "ipv4:127.0.0.1:5000" → "127.0.0.1", "ipv6:[2001:db8::1]:5000" →
// "2001:db8::/64" (also with the brackets percent-encoded, as some gRPC
// versions write them). Anything else is kept whole, as its own group.
std::string grpcPeerGroup(std::string_view peer);

// Why a stream was refused before its first message.
struct GrpcRefusal {
  GrpcCode code = GrpcCode::Unauthenticated;
  std::string message;  // the status message: names what was wrong
  std::string metric;   // haarcast_refusals_total{reason}
};

// The token rule of the WebSocket upgrade, for a stream whose call carries
// `authorization` metadata (empty: none): with a server token, the value
// must be "Bearer <token>"; a wrong one counts as a guess against the
// address, and an address with too many guesses is refused whatever it sends.
std::optional<GrpcRefusal> checkGrpcToken(std::string_view authorization, const std::string& serverToken,
                                          TokenGuard& guard, const std::string& address, Clock::time_point now);

}  // namespace haarcast::net
