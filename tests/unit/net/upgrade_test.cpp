// The upgrade's checks without a socket: their order (path, Origin, token
// limit, token), what each refusal says and counts, and which ones count
// as a token guess.
#include "haarcast/net/upgrade.h"

#include <gtest/gtest.h>

namespace haarcast::net {
namespace {

namespace http = boost::beast::http;

HttpRequest request(const std::string& target, const std::string& origin = "", const std::string& auth = "") {
  HttpRequest r{http::verb::get, target, 11};
  r.set(http::field::host, "render.example:8080");
  if (!origin.empty()) r.set(http::field::origin, origin);
  if (!auth.empty()) r.set(http::field::authorization, auth);
  return r;
}

ServerOptions withToken() {
  ServerOptions o;
  o.allowHosts = {"render.example"};
  o.token = "secret";
  o.tokenGuard.maxFailures = 2;
  o.tokenGuard.lockoutSeconds = 30;
  return o;
}

TEST(Upgrade, ChecksPathThenOriginThenToken) {
  const ServerOptions o = withToken();
  TokenGuard guard(o.tokenGuard);
  const auto now = Clock::now();
  // A wrong path is a 404 even with a foreign Origin and no token.
  auto r = checkUpgrade(request("/socket?token=x", "https://evil.example"), o, guard, "a", now);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, http::status::not_found);
  EXPECT_EQ(r->body, "no WebSocket at /socket (use /ws)\n");
  EXPECT_EQ(r->metric, "");
  // A foreign Origin is refused before the token is looked at.
  r = checkUpgrade(request("/ws?token=x", "https://evil.example"), o, guard, "a", now);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, http::status::forbidden);
  EXPECT_EQ(r->metric, "origin");
  EXPECT_NE(r->logLine.find("https://evil.example"), std::string::npos);
  EXPECT_FALSE(guard.locked("a", now)) << "a refused Origin is not a token guess";
  // The serving host's own page, with the token as a query or a Bearer
  // header (any case), goes on.
  EXPECT_FALSE(checkUpgrade(request("/ws?token=secret", "http://render.example:8080"), o, guard, "a", now));
  EXPECT_FALSE(checkUpgrade(request("/ws", "", "BEARER secret"), o, guard, "a", now));
}

TEST(Upgrade, WrongTokensAreGuessesAndMissingOnesAreNot) {
  const ServerOptions o = withToken();
  TokenGuard guard(o.tokenGuard);
  const auto now = Clock::now();
  for (int i = 0; i < 3; ++i) {
    auto r = checkUpgrade(request("/ws"), o, guard, "a", now);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, http::status::unauthorized);
    EXPECT_TRUE(r->bearerChallenge);
    EXPECT_NE(r->body.find("no token"), std::string::npos);
  }
  EXPECT_FALSE(guard.locked("a", now));
  for (int i = 0; i < 2; ++i) {
    auto r = checkUpgrade(request("/ws?token=guess"), o, guard, "a", now);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->body, "unauthorized: wrong token\n");
    EXPECT_EQ(r->metric, "token");
  }
  // Locked: even the right token waits, with a Retry-After; another address does not.
  auto r = checkUpgrade(request("/ws?token=secret"), o, guard, "a", now);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, http::status::too_many_requests);
  EXPECT_EQ(r->metric, "token_rate");
  EXPECT_EQ(r->retryAfter, "30");
  EXPECT_FALSE(checkUpgrade(request("/ws?token=secret"), o, guard, "b", now));
}

TEST(Upgrade, HostIsCheckedBeforeOrigin) {
  ServerOptions o = withToken();
  TokenGuard guard(o.tokenGuard);
  const auto now = Clock::now();
  // DNS rebinding: evil.example resolves to this server, and its page sends
  // an Origin that matches its Host. The Host is what gives it away.
  HttpRequest rebound = request("/ws?token=secret", "http://evil.example:8080");
  rebound.set(http::field::host, "evil.example:8080");
  auto r = checkUpgrade(rebound, o, guard, "a", now);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, http::status::misdirected_request);
  EXPECT_EQ(r->metric, "host");
  EXPECT_EQ(r->body,
            "misdirected request: Host \"evil.example\" is not a name of this server (allow it with --allow-host "
            "evil.example)\n");
  o.allowHosts.push_back("evil.example");
  EXPECT_FALSE(checkUpgrade(rebound, o, guard, "a", now)) << "an allowed name goes on to the Origin and token";
  // A request without a Host names nothing and is not refused for it.
  HttpRequest bare{http::verb::get, "/ws?token=secret", 10};
  EXPECT_FALSE(checkUpgrade(bare, withToken(), guard, "a", now));
}

TEST(Upgrade, OnlyChunkedAloneIsAcceptedAsTransferEncoding) {
  HttpRequest r{http::verb::get, "/", 11};
  EXPECT_EQ(badTransferCoding(r), "");
  r.set(http::field::transfer_encoding, "Chunked");
  EXPECT_EQ(badTransferCoding(r), "");
  for (const char* bad : {"xchunked", "chunked, identity", "gzip, chunked", "identity", "chunked;x=1", ""}) {
    r.set(http::field::transfer_encoding, bad);
    EXPECT_NE(badTransferCoding(r), "") << bad;
  }
  // Two fields are one list: "chunked, chunked".
  r.set(http::field::transfer_encoding, "chunked");
  r.insert(http::field::transfer_encoding, "chunked");
  EXPECT_NE(badTransferCoding(r), "");
}

TEST(Upgrade, NoTokenConfiguredLetsAnyTokenThrough) {
  ServerOptions o;
  o.allowHosts = {"render.example"};
  TokenGuard guard(o.tokenGuard);
  EXPECT_FALSE(checkUpgrade(request("/ws?token=whatever"), o, guard, "a", Clock::now()));
}

TEST(Upgrade, RefusalBodiesAreOneLine) {
  const ServerOptions o = withToken();
  TokenGuard guard(o.tokenGuard);
  // A control byte in the path (one a lenient parser let through) is escaped
  // in the 404's body, not sent back raw.
  auto r = checkUpgrade(request("/n\nforged: 1"), o, guard, "a", Clock::now());
  ASSERT_TRUE(r);
  EXPECT_EQ(r->body.find('\n'), r->body.size() - 1) << r->body;
  EXPECT_NE(r->body.find("forged"), std::string::npos);
}

}  // namespace
}  // namespace haarcast::net
