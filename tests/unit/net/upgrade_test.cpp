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

TEST(Upgrade, NoTokenConfiguredLetsAnyTokenThrough) {
  ServerOptions o;
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
