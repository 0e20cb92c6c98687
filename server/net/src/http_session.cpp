#include "http_session.h"

#include <fstream>
#include <sstream>

#include <boost/beast/websocket.hpp>

#include "haarcast/net/messages.h"
#include "haarcast/net/upgrade.h"
#include "ws_session.h"

namespace haarcast::net {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;

constexpr std::uintmax_t kMaxStaticFileBytes = 32u << 20;
// Retry-After of a 429 and a 503 (seconds): a hint, not a promise.
constexpr const char* kRetryAfterSeconds = "5";

std::string_view view(beast::string_view s) { return {s.data(), s.size()}; }

bool readFile(const std::filesystem::path& file, std::string& body) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(file, ec);
  if (ec || size > kMaxStaticFileBytes) return false;
  std::ifstream in(file, std::ios::binary);
  if (!in) return false;
  std::ostringstream s;
  s << in.rdbuf();
  body = std::move(s).str();
  return true;
}

}  // namespace

HttpSession::HttpSession(Server::Impl& server, asio::ip::tcp::socket&& socket, Admission::Slot connection,
                         std::string address)
    : server_(server), stream_(std::move(socket)), connectionSlot_(std::move(connection)), address_(std::move(address)) {}

void HttpSession::run() {
  asio::dispatch(stream_.get_executor(), [self = shared_from_this()] { self->doRead(); });
}

void HttpSession::doRead() {
  parser_.emplace();
  limitRequestParser(*parser_);
  stream_.expires_after(toDuration(server_.options.handshakeSeconds));
  http::async_read(stream_, buffer_, *parser_,
                   [self = shared_from_this()](beast::error_code ec, std::size_t) { self->onRead(ec); });
}

void HttpSession::onRead(beast::error_code ec) {
  if (ec == http::error::end_of_stream) {
    stream_.socket().shutdown(asio::ip::tcp::socket::shutdown_send, ec);
    return;
  }
  if (ec) {
    // A request we cannot parse gets a 400 naming why; a timeout is
    // counted; resets just end the connection.
    if (ec == beast::error::timeout) {
      server_.metrics.addTimeout("http_request");
    } else if (ec.category() == http::make_error_code(http::error::bad_target).category()) {
      Request dummy;
      respond(dummy, http::status::bad_request, "bad request: " + ec.message() + "\n", "text/plain", false);
    }
    return;
  }
  auto request = parser_->release();
  // Framing the parser did not act on ("xchunked", "chunked, identity"):
  // where this request's body ends is unknown, so nothing after it on this
  // connection can be trusted either (request smuggling).
  if (std::string bad = badTransferCoding(request); !bad.empty()) {
    server_.metrics.addRefusal("transfer_encoding");
    respond(request, http::status::bad_request, std::move(bad), "text/plain", false);
    return;
  }
  if (websocket::is_upgrade(request)) {
    upgrade(std::move(request));
    return;
  }
  serve(request);
}

void HttpSession::upgrade(Request request) {
  if (auto refusal = checkUpgrade(request, server_.options, server_.tokenGuard, address_, Clock::now())) {
    if (!refusal->metric.empty()) server_.logRefusal(address_, refusal->logLine);
    if (refusal->status == http::status::unauthorized) {
      server_.metrics.addError(errorLabel(v1::ERROR_CODE_UNAUTHORIZED));
    }
    Response res{refusal->status, request.version()};
    if (!refusal->retryAfter.empty()) res.set(http::field::retry_after, refusal->retryAfter);
    if (refusal->bearerChallenge) res.set(http::field::www_authenticate, "Bearer");
    if (refusal->metric.empty()) {
      respond(request, std::move(res), std::move(refusal->body), "text/plain", false);
    } else {
      refuse(request, std::move(res), std::move(refusal->body), refusal->metric.c_str());
    }
    return;
  }
  if (server_.stopping.load()) {
    refuse(request, Response{http::status::service_unavailable, request.version()}, "the server is shutting down\n",
           "draining");
    return;
  }
  // The pre-Hello budget: connections that have not said Hello yet hold
  // little, but a flood of them must not crowd out other addresses (a full
  // budget gives up the largest holder's oldest one: admission.h).
  Admission::Refusal refusal;
  auto pending = server_.admission.take(SlotKind::Pending, address_, &refusal);
  if (!pending) {
    Response res{refusal.perAddress ? http::status::too_many_requests : http::status::service_unavailable,
                 request.version()};
    res.set(http::field::retry_after, kRetryAfterSeconds);
    refuse(request, std::move(res), refusal.reason + "\n", refusal.label.c_str());
    return;
  }
  server_.metrics.addHttpResponse(101);
  std::make_shared<WsSession>(server_, stream_.release_socket(), std::move(connectionSlot_), std::move(*pending),
                              address_)
      ->accept(std::move(request));
}

void HttpSession::refuse(const Request& request, Response res, std::string body, const char* refusal, bool keepAlive) {
  server_.metrics.addRefusal(refusal);
  respond(request, std::move(res), std::move(body), "text/plain", keepAlive);
}

void HttpSession::serve(const Request& request) {
  server_.metrics.httpRequests.fetch_add(1);
  const std::string_view path = targetPath(view(request.target()));
  const bool keepAlive = request.keep_alive() && !server_.stopping.load();
  if (request.method() != http::verb::get && request.method() != http::verb::head) {
    Response res{http::status::method_not_allowed, request.version()};
    res.set(http::field::allow, "GET, HEAD");
    respond(request, std::move(res), "method not allowed: use GET\n", "text/plain", keepAlive);
    return;
  }
  if (path == "/healthz") {
    if (const auto reason = server_.unhealthyReason()) {
      respond(request, http::status::service_unavailable, *reason + "\n", "text/plain", keepAlive);
    } else {
      respond(request, http::status::ok, "ok\n", "text/plain", keepAlive);
    }
    return;
  }
  if (path == "/readyz") {
    if (const auto reason = server_.notReadyReason()) {
      respond(request, http::status::service_unavailable, *reason + "\n", "text/plain", keepAlive);
    } else {
      respond(request, http::status::ok, "ready\n", "text/plain", keepAlive);
    }
    return;
  }
  // Probes answer whatever the Host: they carry nothing a rebinding page
  // could want, and a liveness probe must not fail over a name. Everything
  // else is for the names the operator listed (host_check.h).
  if (auto refusal = checkHost(request, server_.options, address_)) {
    server_.logRefusal(address_, refusal->logLine);
    refuse(request, Response{refusal->status, request.version()}, std::move(refusal->body), refusal->metric.c_str(),
           keepAlive);
    return;
  }
  if (path == "/metrics") {
    respond(request, http::status::ok, server_.metricsText(), "text/plain; version=0.0.4; charset=utf-8",
            keepAlive);
    return;
  }
  std::optional<std::filesystem::path> file;
  if (path == "/haarcast.proto") {
    if (!server_.options.protoFile.empty()) file = server_.options.protoFile;
  } else if (server_.webRoot) {
    file = server_.webRoot->resolve(path);
  }
  std::string body;
  if (file && readFile(*file, body)) {
    respond(request, http::status::ok, std::move(body), std::string(contentType(*file)), keepAlive);
    return;
  }
  respond(request, http::status::not_found, "not found: " + sanitizeForLog(path, 256) + "\n", "text/plain", keepAlive);
}

void HttpSession::respond(const Request& request, http::status status, std::string body, const std::string& type,
                          bool keepAlive) {
  respond(request, Response{status, request.version() ? request.version() : 11}, std::move(body), type, keepAlive);
}

void HttpSession::respond(const Request& request, Response res, std::string body, const std::string& type,
                          bool keepAlive) {
  server_.metrics.addHttpResponse(static_cast<int>(res.result_int()));
  res.set(http::field::server, kServerVersion);
  res.set(http::field::content_type, type);
  res.set(http::field::cache_control, "no-cache");
  res.keep_alive(keepAlive);
  const bool head = request.method() == http::verb::head;
  res.body() = std::move(body);
  res.prepare_payload();  // Content-Length of the body, also for HEAD
  if (head) res.body().clear();
  auto shared = std::make_shared<Response>(std::move(res));
  http::async_write(stream_, *shared, [self = shared_from_this(), shared, keepAlive](beast::error_code ec, std::size_t) {
    if (ec) return;
    if (!keepAlive) {
      self->stream_.socket().shutdown(asio::ip::tcp::socket::shutdown_send, ec);
      return;
    }
    self->doRead();
  });
}

}  // namespace haarcast::net
