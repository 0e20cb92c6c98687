// The server in process on port 0 and synchronous Beast clients: what the
// server tests share. Frames are 32×32 at level 4 on the CPU backend
// (built-in scene); the slice-table cache lives in the build folder.
#pragma once

#include <atomic>
#include <chrono>
#include <optional>
#include <string>
#include <thread>
#include <utility>  // before Asio: its awaitable.hpp uses std::exchange

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <gtest/gtest.h>

#include "haarcast/backends/backends.h"
#include "haarcast/net/server.h"

namespace haarcast::net::test {


namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

inline constexpr const char* kToken = "s3cret";

inline Catalog testCatalog(const render::Scene& scene) {
  Catalog c;
  Catalog::SceneEntry entry{"default", {}, scene.camera, {}, {}};
  for (const auto& o : scene.objects) {
    entry.defaultMaterials.push_back(o.material.name);
    entry.poses.push_back(o.pose);
    entry.objectNames.push_back(o.name);
  }
  c.scenes.push_back(entry);
  c.materials = {"lambert", "phong:16", "phong:64", "ggx:0.3"};
  c.backends = {Backend::Cpu};
  return c;
}

// A session config's render options, as the test builders make them.
inline render::RenderOptions testRenderOptions(const SessionConfig& c) {
  render::RenderOptions options;
  options.level = c.level;
  options.method = c.method;
  options.lightCoefficients = c.lightCoefficients;
  options.cacheDir = HAARCAST_TEST_CACHE_DIR;
  return options;
}

inline RendererBuilder testBuilder() {
  return [](const SessionConfig& c) {
    render::Scene scene = render::defaultScene();
    for (std::size_t i = 0; i < scene.objects.size() && i < c.materials.size(); ++i) {
      if (c.materials[i] != scene.objects[i].material.name) scene.objects[i].material = render::materialFromSpec(c.materials[i]);
    }
    const render::RenderOptions options = testRenderOptions(c);
    auto p = std::make_shared<PreparedRenderer>();
    p->renderer = backends::makeRenderer(std::string(backendName(c.backend)), scene, options);
    return p;
  };
}

inline ServerOptions testOptions() {
  ServerOptions o;
  o.bindAddress = "127.0.0.1";
  o.port = 0;
  o.token = kToken;
  o.limits.maxWidth = 256;
  o.limits.maxHeight = 256;
  o.limits.maxMessageBytes = 4096;
  o.limits.maxFps = 30;
  o.admission.sessions = 8;
  o.defaults.width = 32;
  o.defaults.height = 32;
  o.defaults.level = 4;
  o.defaults.lightCoefficients = 64;
  o.handshakeSeconds = 3;
  o.idleSeconds = 60;
  o.writeStallSeconds = 1.5;
  o.statsSeconds = 0.5;
  o.drainSeconds = 2;
  return o;
}

class TestServer {
 public:
  explicit TestServer(ServerOptions options = testOptions())
      : server_(std::make_unique<Server>(std::move(options), testCatalog(render::defaultScene()), testBuilder())) {
    server_->start();
  }
  TestServer(ServerOptions options, AbandonableRendererBuilder builder)
      : server_(std::make_unique<Server>(std::move(options), testCatalog(render::defaultScene()), std::move(builder))) {
    server_->start();
  }
  ~TestServer() {
    server_->stop();
    server_->wait();
  }
  std::uint16_t port() const { return server_->port(); }
  Server& server() { return *server_; }

 private:
  std::unique_ptr<Server> server_;
};

inline v1::ClientMessage hello(std::uint32_t width = 32, std::uint32_t height = 32, v1::Encoding encoding = v1::ENCODING_JPEG,
                        double fps = 20) {
  v1::ClientMessage m;
  auto* h = m.mutable_hello();
  h->set_protocol_version(kProtocolVersion);
  h->set_width(width);
  h->set_height(height);
  h->set_encoding(encoding);
  h->set_fps_cap(fps);
  h->set_client_name("test");
  return m;
}

inline v1::ClientMessage pose(std::uint64_t sequence, double yaw = 0) {
  v1::ClientMessage m;
  auto* p = m.mutable_pose();
  p->set_sequence(sequence);
  auto* o = p->add_objects();
  o->set_object(0);
  o->mutable_rotate_degrees()->set_y(yaw);
  p->set_client_time_ms(1000.0 + static_cast<double>(sequence));
  return m;
}

// A synchronous WebSocket client with read timeouts (async ops run for a
// bounded time on a private io_context).
class Client {
 public:
  // `from`: the local address to connect from (127.0.0.2 is another
  // client address on Linux loopback); `origin`: an Origin header to send.
  explicit Client(std::uint16_t port, std::string target = std::string("/ws?token=") + kToken, int receiveBuffer = 0,
                  const std::string& from = "", const std::string& origin = "") {
    auto& socket = ws_.next_layer();
    socket.open(tcp::v4());
    if (receiveBuffer > 0) socket.set_option(asio::socket_base::receive_buffer_size(receiveBuffer));
    if (!from.empty()) socket.bind(tcp::endpoint(asio::ip::make_address(from), 0));
    beast::error_code ec;
    socket.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port), ec);
    if (ec) return;
    if (!origin.empty()) {
      ws_.set_option(websocket::stream_base::decorator(
          [origin](websocket::request_type& req) { req.set(http::field::origin, origin); }));
    }
    ws_.handshake(response_, "127.0.0.1:" + std::to_string(port), target, ec);
    connected_ = !ec;
    ws_.binary(true);
    ws_.read_message_max(64u << 20);
  }

  bool connected() const { return connected_; }
  const websocket::response_type& response() const { return response_; }

  void send(const v1::ClientMessage& m) { sendBytes(m.SerializeAsString()); }
  void sendBytes(const std::string& bytes, bool binary = true) {
    ws_.binary(binary);
    beast::error_code ec;
    ws_.write(asio::buffer(bytes), ec);
    ws_.binary(true);
    lastWriteError = ec;
  }

  // The next message, or nullopt when the connection closed or nothing came in time.
  std::optional<v1::ServerMessage> read(std::chrono::milliseconds timeout = 15s) {
    if (closed_) return std::nullopt;
    beast::error_code result = asio::error::timed_out;
    bool done = false;
    buffer_.clear();
    ws_.async_read(buffer_, [&](beast::error_code ec, std::size_t) {
      result = ec;
      done = true;
    });
    ioc_.restart();
    ioc_.run_for(timeout);
    if (!done) {
      beast::error_code ignored;
      ws_.next_layer().cancel(ignored);
      ioc_.restart();
      ioc_.run();
      timedOut = true;
      closed_ = true;
      return std::nullopt;
    }
    if (result) {
      closeError = result;
      closeReason = ws_.reason();
      closed_ = true;
      return std::nullopt;
    }
    v1::ServerMessage m;
    EXPECT_TRUE(m.ParseFromString(beast::buffers_to_string(buffer_.data()))) << "not a ServerMessage";
    return m;
  }

  // The next message of this type; Stats on the way are kept in lastStats.
  std::optional<v1::ServerMessage> expect(v1::ServerMessage::BodyCase body, std::chrono::milliseconds timeout = 20s) {
    const auto deadline = Clock::now() + timeout;
    while (Clock::now() < deadline) {
      auto m = read(std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()));
      if (!m) return std::nullopt;
      if (m->body_case() == body) return m;
      if (m->has_stats()) lastStats = m->stats();
      if (m->has_error() && body != v1::ServerMessage::kError) {
        ADD_FAILURE() << "unexpected Error " << v1::ErrorCode_Name(m->error().code()) << ": " << m->error().message();
      }
    }
    return std::nullopt;
  }

  // The Error the server sends, then the close that follows a fatal one.
  v1::Error expectError(v1::ErrorCode code, bool fatal) {
    auto m = expect(v1::ServerMessage::kError);
    EXPECT_TRUE(m) << "no Error " << v1::ErrorCode_Name(code);
    if (!m) return {};
    EXPECT_EQ(v1::ErrorCode_Name(m->error().code()), v1::ErrorCode_Name(code)) << m->error().message();
    EXPECT_EQ(m->error().fatal(), fatal);
    EXPECT_FALSE(m->error().message().empty());
    if (fatal) expectClosed();
    return m->error();
  }

  void expectClosed() {
    for (int i = 0; i < 100; ++i) {
      auto m = read(10s);
      if (!m) break;
      EXPECT_TRUE(m->has_stats() || m->has_frame()) << "message after a fatal error: " << m->DebugString();
    }
    EXPECT_FALSE(timedOut) << "the server did not close the session";
  }

  // Hello → Welcome.
  v1::Welcome handshake(const v1::ClientMessage& h = hello()) {
    send(h);
    auto w = expect(v1::ServerMessage::kWelcome);
    EXPECT_TRUE(w) << "no Welcome";
    return w ? w->welcome() : v1::Welcome{};
  }

  // Abrupt end: RST, no close handshake.
  void vanish() {
    beast::error_code ec;
    ws_.next_layer().set_option(asio::socket_base::linger(true, 0), ec);
    ws_.next_layer().close(ec);
    closed_ = true;
  }

  beast::error_code lastWriteError, closeError;
  websocket::close_reason closeReason;
  bool timedOut = false;
  v1::Stats lastStats;

 private:
  asio::io_context ioc_;
  websocket::stream<tcp::socket> ws_{ioc_};
  websocket::response_type response_;
  beast::flat_buffer buffer_;
  bool connected_ = false, closed_ = false;
};

// A session that keeps asking for frames on its own thread, counting them.
class HealthySession {
 public:
  explicit HealthySession(std::uint16_t port) {
    thread_ = std::thread([this, port] {
      Client c(port);
      c.handshake();
      std::uint64_t sequence = 0;
      while (running_.load()) {
        ++sequence;
        c.send(pose(sequence, static_cast<double>(sequence)));
        if (!c.expect(v1::ServerMessage::kFrame, 20s)) {
          failed_.store(true);
          return;
        }
        frames_.fetch_add(1);
      }
    });
    EXPECT_TRUE(waitForFrames(1)) << "the healthy session got no first frame";
  }
  ~HealthySession() {
    running_.store(false);
    thread_.join();
  }
  int frames() const { return frames_.load(); }
  // True once `more` frames beyond now have arrived.
  bool waitForFrames(int more, std::chrono::seconds timeout = 30s) {
    const int target = frames_.load() + more;
    const auto deadline = Clock::now() + timeout;
    while (Clock::now() < deadline && !failed_.load()) {
      if (frames_.load() >= target) return true;
      std::this_thread::sleep_for(10ms);
    }
    return frames_.load() >= target;
  }

 private:
  std::atomic<bool> running_{true}, failed_{false};
  std::atomic<int> frames_{0};
  std::thread thread_;
};

inline std::string httpGet(std::uint16_t port, const std::string& target, http::status* status = nullptr,
                           const std::string& host = "127.0.0.1") {
  // (Connect, GET, read: a short request on its own connection.)
  asio::io_context ioc;
  beast::tcp_stream stream(ioc);
  // A bound on the whole exchange: a server that stopped answering fails
  // the test (the read throws) instead of hanging it.
  stream.expires_after(std::chrono::seconds(10));
  stream.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
  http::request<http::empty_body> req{http::verb::get, target, 11};
  req.set(http::field::host, host);
  http::write(stream, req);
  beast::flat_buffer buffer;
  http::response<http::string_body> res;
  http::read(stream, buffer, res);
  if (status) *status = res.result();
  return res.body();
}

// The HTTP status of a WebSocket upgrade request (101 when accepted).
// `from`: the local address to connect from (as Client's).
inline http::status upgradeStatus(std::uint16_t port, const std::string& target, const std::string& authorization = "",
                                  const std::string& origin = "", const std::string& host = "127.0.0.1",
                                  const std::string& from = "") {
  asio::io_context ioc;
  beast::tcp_stream stream(ioc);
  if (!from.empty()) {
    stream.socket().open(tcp::v4());
    stream.socket().bind(tcp::endpoint(asio::ip::make_address(from), 0));
  }
  stream.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
  http::request<http::empty_body> req{http::verb::get, target, 11};
  req.set(http::field::host, host);
  if (!origin.empty()) req.set(http::field::origin, origin);
  req.set(http::field::connection, "Upgrade");
  req.set(http::field::upgrade, "websocket");
  req.set(http::field::sec_websocket_version, "13");
  req.set(http::field::sec_websocket_key, "dGhlIHNhbXBsZSBub25jZQ==");
  if (!authorization.empty()) req.set(http::field::authorization, authorization);
  http::write(stream, req);
  beast::flat_buffer buffer;
  http::response_parser<http::empty_body> parser;
  parser.skip(true);  // headers only: a 101 has no body, a 401's is not needed
  beast::error_code ec;
  http::read_header(stream, buffer, parser, ec);
  return parser.get().result();
}

// ---------------------------------------------------------------- round trip


// The WebSocket target with the test token (and more query).
inline std::string ws(const std::string& query = "") { return std::string("/ws?token=") + kToken + query; }

// The value of one sample line of /metrics ("-1" when absent).
inline long long metric(std::uint16_t port, const std::string& sample) {
  const std::string text = httpGet(port, "/metrics");
  const auto at = text.find("\n" + sample + " ");  // a sample line, not a HELP line
  return at == std::string::npos ? -1 : std::stoll(text.substr(at + sample.size() + 2));
}

}  // namespace haarcast::net::test
