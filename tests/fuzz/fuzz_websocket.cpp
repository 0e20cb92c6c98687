// libFuzzer target: the bytes a client sends on a TCP connection — an HTTP
// request, then, when it was an accepted upgrade, WebSocket frames — over a
// Beast test stream, through what the server runs on a socket: the HTTP
// parser with the server's limits (limitRequestParser), the upgrade checks
// (checkUpgrade: path, Origin, token), the WebSocket handshake and stream
// settings (configureSessionStream: read limit, binary), frame parsing
// (masking, fragmentation, control frames, close codes, UTF-8 of text), and
// each message read handed to a RenderSession (fuzz_session.h). When the
// session closes, the close handshake is started with its code and reason,
// as ws_session.cpp does, and reading goes on until the peer's close or EOF.
//
// Input: byte 0 sets how many bytes each WebSocket read may take (1–256),
// so a frame also arrives split at every point; the rest is the client's
// byte stream, after which the client half-closes. The request is read a
// byte at a time: a client waits for the 101 before it sends frames (RFC
// 6455 §4.1), so none of them sits in the HTTP parser's buffer, which the
// server drops at the upgrade.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include <boost/asio/io_context.hpp>
#include <boost/beast/_experimental/test/stream.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include "fuzz_session.h"
#include "haarcast/net/upgrade.h"

namespace {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using haarcast::net::fuzz::check;

const haarcast::net::ServerOptions& serverOptions() {
  static const haarcast::net::ServerOptions options = haarcast::net::fuzz::fuzzServerOptions();
  return options;
}

// One connection: the request, the upgrade, the session's messages.
class Connection {
 public:
  Connection(boost::asio::io_context& ioc, std::string_view input, std::size_t readSize)
      : stream_(ioc, beast::string_view(input.data(), input.size())), peer_(ioc), readSize_(readSize) {
    stream_.connect(peer_);
    stream_.read_size(1);
    stream_.close_remote();  // after its bytes, the client sends nothing more
  }

  void start() {
    haarcast::net::limitRequestParser(parser_);
    http::async_read(stream_, buffer_, parser_, [this](beast::error_code ec, std::size_t) { onRequest(ec); });
  }

 private:
  static void trace(const char* what, const beast::error_code& ec) {
    if (std::getenv("HAARCAST_FUZZ_TRACE") != nullptr) std::fprintf(stderr, "%s: %s\n", what, ec.message().c_str());
  }

  void onRequest(beast::error_code ec) {
    trace("request", ec);
    if (ec) return;  // the server answers a 400 or just closes; nothing more is read
    HttpRequest request = parser_.release();
    if (!websocket::is_upgrade(request)) return;  // a plain GET: static files, not this target
    const auto now = haarcast::net::Clock::time_point{} + std::chrono::hours(1);
    if (auto refusal = haarcast::net::checkUpgrade(request, serverOptions(), guard_, "192.0.2.1", now)) {
      check(!refusal->body.empty() && refusal->body.back() == '\n');
      check(refusal->body.find('\n') == refusal->body.size() - 1);  // one line: nothing forged from the request
      check(refusal->logLine.find('\n') == std::string::npos);
      trace(refusal->body.c_str(), {});
      return;
    }
    ws_.emplace(std::move(stream_));
    ws_->next_layer().read_size(readSize_);
    haarcast::net::configureSessionStream(*ws_, serverOptions());
    ws_->async_accept(request, [this](beast::error_code ec) {
      trace("handshake", ec);
      if (!ec) read();
    });
  }

  void read() {
    ws_->async_read(message_, [this](beast::error_code ec, std::size_t) {
      if (ec) trace("read", ec);
      if (ec) return;  // a violation, a message over the read limit, the peer's close or EOF
      const std::string bytes = beast::buffers_to_string(message_.data());
      message_.consume(message_.size());
      if (!session_.closed()) {
        session_.receive(bytes, ws_->got_binary());
        if (session_.closed()) {
          ws_->async_close(websocket::close_reason(static_cast<websocket::close_code>(session_.closeCode()),
                                                   session_.closeReason()),
                           [](beast::error_code) {});
        }
      }
      read();  // also while closing: the close handshake needs the peer's close frame
    });
  }

  using HttpRequest = haarcast::net::HttpRequest;
  beast::test::stream stream_;
  beast::test::stream peer_;
  beast::flat_buffer buffer_, message_;
  http::request_parser<http::string_body> parser_;
  std::size_t readSize_;
  haarcast::net::TokenGuard guard_{serverOptions().tokenGuard};
  std::optional<websocket::stream<beast::test::stream>> ws_;
  haarcast::net::fuzz::FuzzSession session_;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  boost::asio::io_context ioc;
  {
    auto connection = std::make_unique<Connection>(
        ioc, std::string_view(reinterpret_cast<const char*>(data + 1), size - 1), std::size_t{data[0]} + 1);
    connection->start();
    // Every handler the input makes ready, never waiting on a timer: the
    // client's bytes are all there, then EOF.
    while (ioc.poll() > 0) {
    }
    // What still waits (a handshake timer) is dropped with the io_context,
    // never run against the connection destroyed here.
    ioc.stop();
  }
  return 0;
}
