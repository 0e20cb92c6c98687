// The access rules without sockets: Origin, the Bearer scheme, token-guess
// limits, slots per address, the accept back-off, text for logs and close
// frames, and the served-files list.
#include "haarcast/net/access.h"
#include "haarcast/net/host_check.h"

#include <cerrno>
#include <fstream>

#include <gtest/gtest.h>

#include "../test_files.h"
#include "haarcast/net/messages.h"
#include "haarcast/net/static_files.h"

namespace haarcast::net {
namespace {

using namespace std::chrono_literals;

TEST(Access, OriginSameHostOrAllowListedOrAbsent) {
  const std::vector<std::string> none;
  const std::vector<std::string> allow = {"https://app.example.com/"};
  EXPECT_TRUE(originAllowed("", "127.0.0.1:8080", none));  // a CLI client sends none
  EXPECT_TRUE(originAllowed("http://127.0.0.1:8080", "127.0.0.1:8080", none));
  EXPECT_TRUE(originAllowed("https://Render.Example.com", "render.example.com", none));  // behind a TLS proxy
  EXPECT_FALSE(originAllowed("http://evil.example", "127.0.0.1:8080", none));
  EXPECT_FALSE(originAllowed("http://127.0.0.1:9999", "127.0.0.1:8080", none));  // another port is another origin
  EXPECT_FALSE(originAllowed("null", "127.0.0.1:8080", none));
  EXPECT_FALSE(originAllowed("http://127.0.0.1:8080.evil.example", "127.0.0.1:8080", none));
  EXPECT_TRUE(originAllowed("https://APP.example.com", "127.0.0.1:8080", allow));
  EXPECT_FALSE(originAllowed("https://app.example.com.evil", "127.0.0.1:8080", allow));
  EXPECT_FALSE(originAllowed("http://a", "", none));  // no Host: nothing to be the same as
}

TEST(Access, HostMustBeAnIpLiteralLocalhostOrAllowed) {
  const std::vector<std::string> none;
  const std::vector<std::string> allow = {"Render.Example.com", "svc:80"};
  EXPECT_TRUE(hostAllowed("127.0.0.1:8080", none));
  EXPECT_TRUE(hostAllowed("10.1.2.3", none));  // a Kubernetes probe by pod IP
  EXPECT_TRUE(hostAllowed("[::1]:8080", none));
  EXPECT_TRUE(hostAllowed("LOCALHOST:8080", none));
  EXPECT_TRUE(hostAllowed("localhost.", none));
  EXPECT_TRUE(hostAllowed("", none));  // HTTP/1.0: no name at all
  EXPECT_FALSE(hostAllowed("evil.example:8080", none));
  EXPECT_FALSE(hostAllowed("127.0.0.1.evil.example", none));
  EXPECT_FALSE(hostAllowed("localhost.evil.example", none));
  EXPECT_TRUE(hostAllowed("render.example.com:443", allow));
  EXPECT_TRUE(hostAllowed("render.example.com.", allow));
  EXPECT_TRUE(hostAllowed("svc", allow));  // the allowed entry's port does not matter
  EXPECT_FALSE(hostAllowed("render.example.com.evil", allow));
  EXPECT_TRUE(hostAllowed("anything.example", {"*"}));
  // Not host[:port]: refused, whatever the allow-list.
  for (const char* bad : {"::1", "[::1", "[::1]x", "a b", "host:", "host:123456", "host:80x", "[abc]"}) {
    EXPECT_FALSE(hostAllowed(bad, {"*"})) << bad;
  }
  EXPECT_EQ(hostName("Render.Example.:8080"), "render.example");
  EXPECT_EQ(hostName("[::1]:80"), "::1");
}

TEST(Access, BearerSchemeIsCaseInsensitive) {
  EXPECT_EQ(bearerToken("Bearer abc"), "abc");
  EXPECT_EQ(bearerToken("bearer abc"), "abc");
  EXPECT_EQ(bearerToken("BEARER   abc "), "abc");
  EXPECT_EQ(bearerToken("Basic abc"), "");
  EXPECT_EQ(bearerToken("Bearerabc"), "");
  EXPECT_EQ(bearerToken("Bearer"), "");
  EXPECT_TRUE(tokensEqual("abc", "abc"));
  EXPECT_FALSE(tokensEqual("abd", "abc"));
  EXPECT_FALSE(tokensEqual("", ""));
}

TEST(Access, LoopbackAddresses) {
  EXPECT_TRUE(isLoopbackAddress("127.0.0.1"));
  EXPECT_TRUE(isLoopbackAddress("127.0.0.2"));
  EXPECT_TRUE(isLoopbackAddress("::1"));
  EXPECT_TRUE(isLoopbackAddress("::ffff:127.0.0.1"));
  EXPECT_FALSE(isLoopbackAddress("0.0.0.0"));
  EXPECT_FALSE(isLoopbackAddress("::"));
  EXPECT_FALSE(isLoopbackAddress("10.0.0.1"));
  EXPECT_FALSE(isLoopbackAddress("not an address"));
}

TEST(Access, IPv6PeersAreLimitedPerSlash64) {
  EXPECT_EQ(clientGroup("2001:db8:1:2:aaaa:bbbb:cccc:1"), "2001:db8:1:2::/64");
  EXPECT_EQ(clientGroup("2001:db8:1:2::ffff"), clientGroup("2001:db8:1:2:1234::9"));
  EXPECT_NE(clientGroup("2001:db8:1:3::1"), clientGroup("2001:db8:1:2::1"));
  EXPECT_EQ(clientGroup("::ffff:192.0.2.7"), "192.0.2.7") << "an IPv4-mapped peer is its IPv4 address";
  EXPECT_EQ(clientGroup("192.0.2.7"), "192.0.2.7");
  EXPECT_EQ(clientGroup("::1"), "::1");
  EXPECT_EQ(clientGroup("?"), "?");
  // The point: a host walking its /64 meets one cap.
  Admission::Limits limits;
  limits.connectionsPerAddress = 2;
  Admission admission(limits);
  auto a = admission.take(SlotKind::Connection, clientGroup("2001:db8::1"));
  auto b = admission.take(SlotKind::Connection, clientGroup("2001:db8::2"));
  EXPECT_TRUE(a && b);
  EXPECT_FALSE(admission.take(SlotKind::Connection, clientGroup("2001:db8::3")));
  EXPECT_TRUE(admission.take(SlotKind::Connection, clientGroup("2001:db8:0:1::3")));
}

TEST(Access, TokenGuessesLockAnAddressForAWhile) {
  TokenGuard guard({3, 60.0, 30.0});
  const auto t0 = Clock::now();
  guard.failed("10.0.0.1", t0);
  guard.failed("10.0.0.1", t0 + 1s);
  EXPECT_FALSE(guard.locked("10.0.0.1", t0 + 2s));
  guard.failed("10.0.0.1", t0 + 2s);
  EXPECT_TRUE(guard.locked("10.0.0.1", t0 + 3s));
  EXPECT_FALSE(guard.locked("10.0.0.2", t0 + 3s)) << "another address is not locked";
  EXPECT_FALSE(guard.locked("10.0.0.1", t0 + 33s)) << "the lockout ends";
  // Failures spread beyond the window do not add up.
  TokenGuard slow({2, 10.0, 30.0});
  slow.failed("a", t0);
  slow.failed("a", t0 + 11s);
  EXPECT_FALSE(slow.locked("a", t0 + 12s));
}

TEST(Access, SlotsPerServerAndPerAddress) {
  Admission a({/*connectionsPerAddress*/ 3, /*pending*/ 4, /*pendingPerAddress*/ 2, /*sessions*/ 3,
               /*sessionsPerAddress*/ 2});
  Admission::Refusal why;
  auto s1 = a.take(SlotKind::Session, "A");
  auto s2 = a.take(SlotKind::Session, "A");
  ASSERT_TRUE(s1 && s2);
  EXPECT_FALSE(a.take(SlotKind::Session, "A", &why));
  EXPECT_TRUE(why.perAddress);
  EXPECT_NE(why.reason.find("each address may have 2"), std::string::npos) << why.reason;
  auto s3 = a.take(SlotKind::Session, "B");  // A's cap does not keep B out
  ASSERT_TRUE(s3);
  EXPECT_FALSE(a.take(SlotKind::Session, "C", &why));  // the server's cap
  EXPECT_FALSE(why.perAddress);
  EXPECT_EQ(a.count(SlotKind::Session), 3);
  s1.reset();  // released with its holder
  EXPECT_EQ(a.count(SlotKind::Session, "A"), 1);
  EXPECT_TRUE(a.take(SlotKind::Session, "C"));
  // Kinds are counted apart: pending slots do not use session slots.
  auto p = a.take(SlotKind::Pending, "A");
  ASSERT_TRUE(p);
  Admission::Slot moved = std::move(*p);
  EXPECT_EQ(a.count(SlotKind::Pending), 1);
  moved.release();
  EXPECT_EQ(a.count(SlotKind::Pending), 0);
}

TEST(Access, AcceptBacksOffOnDescriptorExhaustionOnly) {
  AcceptBackoff b;
  auto step = b.onError(EMFILE);
  EXPECT_EQ(step.pause, AcceptBackoff::kFirst);
  EXPECT_TRUE(step.episodeStarted);
  std::chrono::milliseconds last = step.pause;
  for (int i = 0; i < 10; ++i) {
    step = b.onError(ENFILE);
    EXPECT_FALSE(step.episodeStarted) << "one log line per episode";
    EXPECT_GE(step.pause, last);
    last = step.pause;
  }
  EXPECT_EQ(last, AcceptBackoff::kMost);
  EXPECT_TRUE(b.onSuccess());
  EXPECT_FALSE(b.onSuccess());
  EXPECT_EQ(b.onError(ECONNABORTED).pause.count(), 0) << "a peer's abort is retried at once";
  EXPECT_TRUE(b.onError(EMFILE).episodeStarted);
}

TEST(Access, Utf8CutsAndLogSanitising) {
  EXPECT_EQ(utf8Prefix("abc", 5), "abc");
  EXPECT_EQ(utf8Prefix("ab€", 4), "ab");  // € is 3 bytes: not split
  EXPECT_EQ(utf8Prefix("ab€", 5), "ab€");
  EXPECT_EQ(closeReason(std::string(200, 'x')).size(), kMaxCloseReasonBytes);
  EXPECT_EQ(sanitizeForLog("a\nb\r\"c\"\x1b[31m\\"), "a\\nb\\r\\\"c\\\"\\x1b[31m\\\\");
  EXPECT_EQ(sanitizeForLog(std::string(100, 'n'), 8), "nnnnnnnn…");
  EXPECT_EQ(sanitizeForLog("naïve"), "naïve");
}

TEST(Access, WebRootServesOnlyTheListedClientFiles) {
  namespace fs = std::filesystem;
  const haarcast::testing::TempDir dir("haarcast-webroot-");
  const fs::path root = dir.path();
  fs::create_directories(root / "vendor");
  fs::create_directories(root / "node_modules" / "x");
  for (const char* f : {"index.html", "app.js", "vendor/protobuf.min.js", "package.json", ".gitignore",
                        "node_modules/x/index.js"}) {
    std::ofstream(root / f) << "x";
  }
  EXPECT_THROW(WebRoot::load(root), std::invalid_argument) << "no served_files.txt";
  std::ofstream(root / kServedFilesName) << "# the client\nindex.html\napp.js\nvendor/protobuf.min.js\nmissing.js\n";
  const WebRoot web = WebRoot::load(root);
  EXPECT_EQ(web.resolve("/"), fs::canonical(root / "index.html"));
  EXPECT_EQ(web.resolve("/app.js"), fs::canonical(root / "app.js"));
  EXPECT_EQ(web.resolve("/vendor/protobuf.min.js"), fs::canonical(root / "vendor" / "protobuf.min.js"));
  for (const char* refused : {"/package.json", "/.gitignore", "/node_modules/x/index.js", "/missing.js",
                              "/vendor/../package.json", "/served_files.txt"}) {
    EXPECT_EQ(web.resolve(refused), std::nullopt) << refused;
  }
  for (const char* bad : {"../secret\n", ".env\n", "/etc/passwd\n", "node_modules/.bin/x\n"}) {
    std::ofstream(root / kServedFilesName) << "index.html\n" << bad;
    EXPECT_THROW(WebRoot::load(root), std::invalid_argument) << bad;
  }
}

}  // namespace
}  // namespace haarcast::net
