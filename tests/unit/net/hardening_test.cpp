// The server's defences with real sockets: Origin at the upgrade, token
// guesses, slots that one address cannot exhaust for another (127.0.0.1 and
// 127.0.0.2 are two client addresses on Linux loopback), a Ping burst told
// and counted, WebSocket violations counted, /readyz, and the web root.
#include <thread>

#include "haarcast/net/messages.h"
#include "server_fixture.h"

namespace haarcast::net::test {
namespace {

TEST(ServerHardening, ForeignOriginIs403NoOriginAndAllowedOnesPass) {
  auto options = testOptions();
  options.allowOrigins = {"https://app.example.com"};
  TestServer server(options);
  const auto port = server.port();
  const std::string host = "127.0.0.1:" + std::to_string(port);
  EXPECT_EQ(upgradeStatus(port, ws(), "", "http://evil.example", host), http::status::forbidden);
  EXPECT_EQ(upgradeStatus(port, ws(), "", "null", host), http::status::forbidden);
  EXPECT_EQ(upgradeStatus(port, ws(), "", "", host), http::status::switching_protocols);  // a CLI client
  EXPECT_EQ(upgradeStatus(port, ws(), "", "http://" + host, host), http::status::switching_protocols);
  EXPECT_EQ(upgradeStatus(port, ws(), "", "https://app.example.com", host), http::status::switching_protocols);
  EXPECT_EQ(metric(port, "haarcast_http_responses_total{status=\"403\"}"), 2);
  EXPECT_EQ(metric(port, "haarcast_refusals_total{reason=\"origin\"}"), 2);
}

TEST(ServerHardening, TokenGuessesAreRateLimitedPerAddress) {
  auto options = testOptions();
  options.tokenGuard = {3, 60.0, 60.0};
  TestServer server(options);
  const auto port = server.port();
  for (int i = 0; i < 3; ++i) EXPECT_EQ(upgradeStatus(port, "/ws?token=guess"), http::status::unauthorized);
  // Locked: even the right token waits, with any case of "Bearer".
  EXPECT_EQ(upgradeStatus(port, "/ws", std::string("bEaReR ") + kToken), http::status::too_many_requests);
  Client other(port, ws(), 0, "127.0.0.2");
  EXPECT_TRUE(other.connected()) << "another address is not locked";
  other.handshake();
}

TEST(ServerHardening, OneAddressCannotKeepAnotherOut) {
  auto options = testOptions();
  options.admission = {/*connectionsPerAddress*/ 16, /*pending*/ 32, /*pendingPerAddress*/ 4, /*sessions*/ 8,
                       /*sessionsPerAddress*/ 4};
  TestServer server(options);
  const auto port = server.port();
  // 64 sessions from one address that say Hello and then only ping.
  std::vector<std::unique_ptr<Client>> pinging;
  int admitted = 0;
  for (int i = 0; i < 64; ++i) {
    auto c = std::make_unique<Client>(port, ws(), 0, "127.0.0.1");
    if (!c->connected()) continue;
    c->send(hello());
    const auto m = c->read(10s);
    if (m && m->has_welcome()) {
      ++admitted;
      pinging.push_back(std::move(c));
    }
  }
  EXPECT_EQ(admitted, 4) << "the per-address session cap";
  // 64 connections from the same address that never say Hello.
  std::vector<std::unique_ptr<Client>> silent;
  for (int i = 0; i < 64; ++i) silent.push_back(std::make_unique<Client>(port, ws(), 0, "127.0.0.1"));
  for (auto& c : pinging) {
    v1::ClientMessage ping;
    ping.mutable_ping()->set_nonce(7);
    c->send(ping);
  }
  // A second address still gets a session and frames.
  Client second(port, ws(), 0, "127.0.0.2");
  ASSERT_TRUE(second.connected());
  second.handshake();
  second.send(pose(1));
  EXPECT_TRUE(second.expect(v1::ServerMessage::kFrame));
  EXPECT_GT(metric(port, "haarcast_refusals_total{reason=\"pending_per_address\"}"), 0);
  EXPECT_EQ(metric(port, "haarcast_sessions"), 5);
}

TEST(ServerHardening, PingBurstGetsAnErrorACloseCodeAndIsCounted) {
  TestServer server;
  HealthySession healthy(server.port());
  Client c(server.port());
  c.handshake();
  v1::ClientMessage ping;
  ping.mutable_ping()->set_nonce(1);
  const std::string bytes = ping.SerializeAsString();
  for (int i = 0; i < 3000 && !c.lastWriteError; ++i) c.sendBytes(bytes);  // not reading meanwhile
  std::optional<v1::Error> error;
  while (auto m = c.read(10s)) {
    if (m->has_error()) error = m->error();
  }
  ASSERT_TRUE(error) << "no Error before the close";
  EXPECT_EQ(v1::ErrorCode_Name(error->code()), "ERROR_CODE_OVERLOADED") << error->message();
  EXPECT_TRUE(error->fatal());
  EXPECT_EQ(c.closeReason.code, static_cast<std::uint16_t>(CloseCode::PolicyError));
  EXPECT_EQ(metric(server.port(), "haarcast_session_cuts_total{reason=\"overloaded\"}"), 1);
  EXPECT_TRUE(healthy.waitForFrames(2));
}

TEST(ServerHardening, WebSocketViolationsAreCounted) {
  TestServer server;
  asio::io_context ioc;
  tcp::socket s(ioc);
  s.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), server.port()));
  const std::string upgrade = "GET " + ws() +
                              " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: Upgrade\r\nUpgrade: websocket\r\n"
                              "Sec-WebSocket-Version: 13\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n";
  asio::write(s, asio::buffer(upgrade));
  asio::streambuf response;
  asio::read_until(s, response, "\r\n\r\n");
  asio::write(s, asio::buffer(std::string("\x82\x01x", 3)));  // unmasked: RFC 6455 §5.1 says close
  beast::error_code ec;
  char sink[256];
  for (int i = 0; i < 100 && !ec; ++i) s.read_some(asio::buffer(sink), ec);  // the close frame, then EOF
  s.close();  // Beast's teardown waits for our end of the TCP connection
  const auto deadline = Clock::now() + 5s;
  while (Clock::now() < deadline && metric(server.port(), "haarcast_websocket_violations_total{kind=\"protocol\"}") != 1) {
    std::this_thread::sleep_for(20ms);
  }
  EXPECT_EQ(metric(server.port(), "haarcast_websocket_violations_total{kind=\"protocol\"}"), 1);
}

TEST(ServerHardening, ReadyzFollowsTheSessionBudgetAndTheDrain) {
  auto options = testOptions();
  options.admission.sessions = 1;
  TestServer server(options);
  const auto port = server.port();
  http::status status{};
  httpGet(port, "/readyz", &status);
  EXPECT_EQ(status, http::status::ok);
  {
    Client c(port);
    httpGet(port, "/readyz", &status);
    EXPECT_EQ(status, http::status::ok) << "a connection without a Hello holds no session slot";
    c.handshake();
    httpGet(port, "/readyz", &status);
    EXPECT_EQ(status, http::status::service_unavailable);
    EXPECT_TRUE(server.server().atCapacity());
    EXPECT_EQ(metric(port, "haarcast_budget_in_use{budget=\"sessions\"}"), 1);
    EXPECT_EQ(metric(port, "haarcast_capacity{budget=\"sessions\"}"), 1);
  }  // closed
  const auto deadline = Clock::now() + 5s;
  do {
    httpGet(port, "/readyz", &status);
  } while (status != http::status::ok && Clock::now() < deadline && (std::this_thread::sleep_for(20ms), true));
  EXPECT_EQ(status, http::status::ok);
  // A connection without a Hello holds no session slot but keeps the drain
  // going (it does not read the close): 503 while draining, below capacity.
  Client open(port);
  ASSERT_TRUE(open.connected());
  server.server().stop();
  EXPECT_EQ(httpGet(port, "/readyz", &status), "draining\n");
  EXPECT_EQ(status, http::status::service_unavailable);
  EXPECT_EQ(httpGet(port, "/healthz", &status), "ok\n");
}

TEST(ServerHardening, WebRootServesTheClientOnly) {
  auto options = testOptions();
  options.webRoot = std::filesystem::path(HAARCAST_SOURCE_DIR) / "client" / "web";
  TestServer server(options);
  http::status status{};
  EXPECT_NE(httpGet(server.port(), "/", &status).find("<html"), std::string::npos);
  EXPECT_EQ(status, http::status::ok);
  for (const char* file : {"/app.js", "/style.css", "/frame_stats.js", "/page_params.js"}) {
    httpGet(server.port(), file, &status);
    EXPECT_EQ(status, http::status::ok) << file;
  }
  for (const char* file : {"/package.json", "/package-lock.json", "/.gitignore", "/scripts/vendor.mjs",
                           "/node_modules/protobufjs/package.json", "/served_files.txt"}) {
    httpGet(server.port(), file, &status);
    EXPECT_EQ(status, http::status::not_found) << file;
  }
}

}  // namespace
}  // namespace haarcast::net::test
