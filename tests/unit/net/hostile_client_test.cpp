// The attacks of a hostile-client probe, rerun against a server in process:
// DNS rebinding (Host), request framing (Transfer-Encoding), a few
// addresses that try to fill the pre-Hello and session budgets (127.0.0.x
// are distinct client addresses on Linux loopback), and a token spray from
// many addresses.
#include <thread>

#include "haarcast/net/messages.h"
#include "server_fixture.h"

namespace haarcast::net::test {
namespace {

// Sends `request` as raw bytes and returns the response's status line.
std::string rawStatusLine(std::uint16_t port, const std::string& request) {
  asio::io_context ioc;
  beast::tcp_stream stream(ioc);
  stream.expires_after(std::chrono::seconds(10));
  stream.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
  asio::write(stream.socket(), asio::buffer(request));
  beast::flat_buffer buffer;
  http::response<http::string_body> res;
  beast::error_code ec;
  http::read(stream, buffer, res, ec);
  if (ec) return "no response: " + ec.message();
  return std::to_string(res.result_int()) + " " + res.body();
}

TEST(HostileClient, DnsRebindingIsRefusedByTheHostCheck) {
  auto options = testOptions();
  options.token.clear();  // the default: loopback, no token
  options.allowHosts = {"render.example"};
  TestServer server(options);
  const auto port = server.port();
  const std::string p = std::to_string(port);
  // evil.example rebound to 127.0.0.1: its page's Origin matches its Host.
  EXPECT_EQ(upgradeStatus(port, "/ws", "", "http://evil.example:" + p, "evil.example:" + p),
            http::status::misdirected_request);
  http::status status{};
  const std::string body = httpGet(port, "/metrics", &status, "evil.example:" + p);
  EXPECT_EQ(status, http::status::misdirected_request);
  EXPECT_NE(body.find("--allow-host evil.example"), std::string::npos) << body;
  httpGet(port, "/haarcast.proto", &status, "evil.example:" + p);
  EXPECT_EQ(status, http::status::misdirected_request);
  // Probes answer whatever the Host.
  EXPECT_EQ(httpGet(port, "/healthz", &status, "evil.example:" + p), "ok\n");
  httpGet(port, "/readyz", &status, "evil.example:" + p);
  EXPECT_EQ(status, http::status::ok);
  // The names the operator allows, IP literals and localhost pass.
  EXPECT_EQ(upgradeStatus(port, "/ws", "", "http://render.example:" + p, "render.example:" + p),
            http::status::switching_protocols);
  EXPECT_EQ(upgradeStatus(port, "/ws", "", "http://localhost:" + p, "localhost:" + p),
            http::status::switching_protocols);
  httpGet(port, "/metrics", &status, "[::1]:" + p);
  EXPECT_EQ(status, http::status::ok);
  EXPECT_EQ(metric(port, "haarcast_refusals_total{reason=\"host\"}"), 3);
}

// RFC 9112 §3.2: two Host fields, or none in HTTP/1.1, are a bad request,
// for every path the host check guards (probes answer whatever the Host).
TEST(HostileClient, TwoHostFieldsOrNoneAre400) {
  auto options = testOptions();
  options.token.clear();
  TestServer server(options);
  const auto port = server.port();
  EXPECT_EQ(rawStatusLine(port, "GET /metrics HTTP/1.1\r\nHost: 127.0.0.1\r\nHost: evil.example\r\n\r\n").substr(0, 3), "400");
  EXPECT_EQ(rawStatusLine(port, "GET /metrics HTTP/1.1\r\nHost: 127.0.0.1\r\nHost: 127.0.0.1\r\n\r\n").substr(0, 3), "400");
  EXPECT_EQ(rawStatusLine(port, "GET /metrics HTTP/1.1\r\n\r\n").substr(0, 3), "400");
  EXPECT_EQ(rawStatusLine(port, "GET /ws HTTP/1.1\r\nHost: a\r\nHost: b\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                                "Sec-WebSocket-Version: 13\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n")
                .substr(0, 3),
            "400");
  EXPECT_EQ(rawStatusLine(port, "GET /metrics HTTP/1.0\r\n\r\n").substr(0, 3), "200") << "HTTP/1.0 may omit the Host";
  EXPECT_EQ(rawStatusLine(port, "GET /metrics HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n").substr(0, 3), "200");
  EXPECT_EQ(rawStatusLine(port, "GET /healthz HTTP/1.1\r\nHost: a\r\nHost: b\r\n\r\n"), "200 ok\n") << "probes answer";
  EXPECT_EQ(metric(port, "haarcast_refusals_total{reason=\"host\"}"), 4);
}

TEST(HostileClient, UnknownTransferCodingsAre400) {
  TestServer server;
  const auto port = server.port();
  const auto get = [](const std::string& coding) {
    return "GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\nTransfer-Encoding: " + coding + "\r\n\r\n";
  };
  EXPECT_EQ(rawStatusLine(port, get("xchunked")).substr(0, 3), "400");
  EXPECT_EQ(rawStatusLine(port, get("chunked, identity")).substr(0, 3), "400");
  EXPECT_EQ(rawStatusLine(port, get("chunked") + "0\r\n\r\n"), "200 ok\n");
  EXPECT_EQ(rawStatusLine(port, "GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"), "200 ok\n");
  EXPECT_EQ(metric(port, "haarcast_refusals_total{reason=\"transfer_encoding\"}"), 2);
}

std::string from(int i) { return "127.0.0." + std::to_string(i + 2); }

TEST(HostileClient, EightAddressesOfSilentUpgradesDoNotKeepANinthOut) {
  auto options = testOptions();
  options.admission = {/*connectionsPerAddress*/ 32, /*pending*/ 16, /*pendingPerAddress*/ 2, /*sessions*/ 8,
                       /*sessionsPerAddress*/ 4};
  TestServer server(options);
  const auto port = server.port();
  std::vector<std::unique_ptr<Client>> silent;
  for (int i = 0; i < 8; ++i) {
    for (int j = 0; j < 2; ++j) {
      silent.push_back(std::make_unique<Client>(port, ws(), 0, from(i)));
      ASSERT_TRUE(silent.back()->connected());
    }
  }
  EXPECT_EQ(metric(port, "haarcast_pending_connections"), 16);
  http::status status{};
  httpGet(port, "/readyz", &status);
  EXPECT_EQ(status, http::status::ok);
  // A ninth address is let in, and what /readyz said holds: it gets a session.
  Client ninth(port, ws(), 0, "127.0.0.100");
  ASSERT_TRUE(ninth.connected());
  ninth.handshake();
  // The oldest silent connection of a largest holder made way, and was closed.
  EXPECT_FALSE(silent.front()->read(5s)) << "the evicted connection is still open";
  EXPECT_FALSE(silent.front()->timedOut);
  EXPECT_EQ(metric(port, "haarcast_session_cuts_total{reason=\"pending_evicted\"}"), 1);
}

TEST(HostileClient, FourAddressesCannotFillTheSessionsAndReadyzSaysWhenFull) {
  auto options = testOptions();
  options.admission = {/*connectionsPerAddress*/ 32, /*pending*/ 64, /*pendingPerAddress*/ 16, /*sessions*/ 16,
                       /*sessionsPerAddress*/ 8};  // the reserve: min(8, 16 / 4) = 4
  TestServer server(options);
  const auto port = server.port();
  std::vector<std::unique_ptr<Client>> idle;
  const auto trySession = [&](const std::string& address) {
    auto c = std::make_unique<Client>(port, ws(), 0, address);
    if (!c->connected()) return false;
    c->send(hello());
    const auto m = c->read(10s);
    if (!m || !m->has_welcome()) return false;
    idle.push_back(std::move(c));
    return true;
  };
  // Two addresses, eight tries each: 8 + 4, then the reserve of 4 holds.
  int admitted = 0;
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 8; ++j) admitted += trySession(from(i)) ? 1 : 0;
  }
  EXPECT_EQ(admitted, 12);
  EXPECT_GT(metric(port, "haarcast_refusals_total{reason=\"sessions_reserved\"}"), 0);
  http::status status{};
  httpGet(port, "/readyz", &status);
  EXPECT_EQ(status, http::status::ok);
  // New addresses take the reserve, one each; /readyz turns 503 when the next
  // new address would be refused, and it is.
  for (int i = 2; i < 6; ++i) {
    httpGet(port, "/readyz", &status);
    EXPECT_EQ(status, http::status::ok);
    EXPECT_TRUE(trySession(from(i))) << from(i);
  }
  httpGet(port, "/readyz", &status);
  EXPECT_EQ(status, http::status::service_unavailable);
  EXPECT_FALSE(trySession(from(7)));
}

TEST(HostileClient, ATokenSprayFromManyAddressesIsLimitedServerWide) {
  TestServer server;  // the default guard: 100 wrong tokens a minute across the server
  const auto port = server.port();
  EXPECT_EQ(upgradeStatus(port, ws(), "", "", "127.0.0.1", "127.0.0.1"), http::status::switching_protocols);
  int unauthorized = 0, limited = 0;
  const auto t0 = Clock::now();
  for (int i = 0; i < 1000; ++i) {
    const auto s = upgradeStatus(port, "/ws?token=guess" + std::to_string(i), "", "", "127.0.0.1", from(i % 200));
    unauthorized += s == http::status::unauthorized ? 1 : 0;
    limited += s == http::status::too_many_requests ? 1 : 0;
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  std::printf("1000 guesses from 200 addresses in %.2f s: %d × 401, %d × 429\n", seconds, unauthorized, limited);
  EXPECT_EQ(unauthorized, 100);
  EXPECT_EQ(limited, 900);
  EXPECT_EQ(metric(port, "haarcast_refusals_total{reason=\"token_rate_server\"}"), 900);
  // A client that has shown the right token goes on; a new address waits.
  EXPECT_EQ(upgradeStatus(port, ws(), "", "", "127.0.0.1", "127.0.0.1"), http::status::switching_protocols);
  EXPECT_EQ(upgradeStatus(port, ws(), "", "", "127.0.0.1", "127.0.0.250"), http::status::too_many_requests);
}

}  // namespace
}  // namespace haarcast::net::test
