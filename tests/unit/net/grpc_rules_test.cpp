// The gRPC transport's rules without gRPC: the status that ends a failed
// stream, the peer string's client group, and the token in metadata.
#include <gtest/gtest.h>

#include "haarcast/net/grpc_rules.h"

namespace haarcast::net {
namespace {

TEST(GrpcRules, FatalErrorsEndWithTheStatusThatSaysTheSame) {
  EXPECT_EQ(grpcCodeFor(v1::ERROR_CODE_UNAUTHORIZED), GrpcCode::Unauthenticated);
  EXPECT_EQ(grpcCodeFor(v1::ERROR_CODE_TOO_MANY_SESSIONS), GrpcCode::ResourceExhausted);
  EXPECT_EQ(grpcCodeFor(v1::ERROR_CODE_OVERLOADED), GrpcCode::ResourceExhausted);
  EXPECT_EQ(grpcCodeFor(v1::ERROR_CODE_MESSAGE_TOO_LARGE), GrpcCode::ResourceExhausted);
  EXPECT_EQ(grpcCodeFor(v1::ERROR_CODE_SHUTTING_DOWN), GrpcCode::Unavailable);
  EXPECT_EQ(grpcCodeFor(v1::ERROR_CODE_TIMEOUT), GrpcCode::DeadlineExceeded);
  EXPECT_EQ(grpcCodeFor(v1::ERROR_CODE_PROTOCOL_ORDER), GrpcCode::FailedPrecondition);
  EXPECT_EQ(grpcCodeFor(v1::ERROR_CODE_RENDER_FAILED), GrpcCode::Internal);
  for (const auto code : {v1::ERROR_CODE_BAD_MESSAGE, v1::ERROR_CODE_UNSUPPORTED_VERSION, v1::ERROR_CODE_BAD_RESOLUTION,
                          v1::ERROR_CODE_BAD_SETTINGS, v1::ERROR_CODE_UNKNOWN_SCENE, v1::ERROR_CODE_UNKNOWN_MATERIAL}) {
    EXPECT_EQ(grpcCodeFor(code), GrpcCode::InvalidArgument) << v1::ErrorCode_Name(code);
  }
}

TEST(GrpcRules, PeerStringsNameTheClientGroupOfTheirAddress) {
  EXPECT_EQ(grpcPeerGroup("ipv4:127.0.0.1:50123"), "127.0.0.1");
  EXPECT_EQ(grpcPeerGroup("ipv4:10.1.2.3:1"), "10.1.2.3");
  EXPECT_EQ(grpcPeerGroup("ipv6:[::1]:50123"), "::1");
  // An IPv6 client counts by its /64, as on the WebSocket side; gRPC writes
  // the brackets percent-encoded in some versions.
  EXPECT_EQ(grpcPeerGroup("ipv6:[2001:db8:1:2:aaaa::1]:443"), "2001:db8:1:2::/64");
  EXPECT_EQ(grpcPeerGroup("ipv6:%5B2001:db8:1:2:bbbb::9%5D:443"), "2001:db8:1:2::/64");
  EXPECT_EQ(grpcPeerGroup("ipv6:[::ffff:192.0.2.7]:80"), "192.0.2.7");
  EXPECT_EQ(grpcPeerGroup("unix:/tmp/socket"), "unix:/tmp/socket");
  EXPECT_EQ(grpcPeerGroup("ipv6:[broken"), "ipv6:[broken");
}

TEST(GrpcRules, TokenInMetadataIsCheckedAndWrongOnesAreGuesses) {
  TokenGuard guard({2, 60.0, 60.0});
  const auto now = Clock::now();
  EXPECT_FALSE(checkGrpcToken("", "", guard, "a", now)) << "no server token: anyone";
  EXPECT_FALSE(checkGrpcToken("Bearer s3cret", "s3cret", guard, "a", now));
  EXPECT_FALSE(checkGrpcToken("bearer s3cret", "s3cret", guard, "a", now)) << "the scheme in any case";

  const auto missing = checkGrpcToken("", "s3cret", guard, "a", now);
  ASSERT_TRUE(missing);
  EXPECT_EQ(missing->code, GrpcCode::Unauthenticated);
  EXPECT_NE(missing->message.find("authorization: Bearer"), std::string::npos) << missing->message;
  EXPECT_FALSE(guard.locked("a", now)) << "no token is not a guess";

  const auto wrong = checkGrpcToken("Bearer nope", "s3cret", guard, "a", now);
  ASSERT_TRUE(wrong);
  EXPECT_EQ(wrong->code, GrpcCode::Unauthenticated);
  EXPECT_EQ(wrong->metric, "token");
  EXPECT_FALSE(guard.locked("a", now));
  ASSERT_TRUE(checkGrpcToken("Basic czNjcmV0", "s3cret", guard, "a", now));
  EXPECT_FALSE(guard.locked("a", now)) << "another scheme carries no token: not a guess";
  ASSERT_TRUE(checkGrpcToken("Bearer wrong-again", "s3cret", guard, "a", now));
  EXPECT_TRUE(guard.locked("a", now)) << "two guesses lock the address";

  const auto locked = checkGrpcToken("Bearer s3cret", "s3cret", guard, "a", now);
  ASSERT_TRUE(locked) << "a locked address is refused even with the right token";
  EXPECT_EQ(locked->code, GrpcCode::ResourceExhausted);
  EXPECT_EQ(locked->metric, "token_rate");
  EXPECT_FALSE(checkGrpcToken("Bearer s3cret", "s3cret", guard, "b", now)) << "another address is not";
}

// A spray from many addresses sets the server-wide lock: it is named as
// such, and a client that has shown the right token before still passes.
TEST(GrpcRules, AServerWideLockSparesKnownClients) {
  TokenGuard guard({100, 60.0, 60.0, 10, 4096});
  const auto now = Clock::now();
  EXPECT_FALSE(checkGrpcToken("Bearer s3cret", "s3cret", guard, "known", now));
  for (int i = 0; i < 10; ++i) checkGrpcToken("Bearer guess", "s3cret", guard, "sprayer-" + std::to_string(i), now);
  const auto newcomer = checkGrpcToken("Bearer s3cret", "s3cret", guard, "new", now);
  ASSERT_TRUE(newcomer) << "an address that never showed the token waits out the server-wide lock";
  EXPECT_EQ(newcomer->code, GrpcCode::ResourceExhausted);
  EXPECT_EQ(newcomer->metric, "token_rate_server");
  EXPECT_NE(newcomer->message.find("many addresses"), std::string::npos) << newcomer->message;
  EXPECT_FALSE(checkGrpcToken("Bearer s3cret", "s3cret", guard, "known", now)) << "a known client goes on";
}

}  // namespace
}  // namespace haarcast::net
