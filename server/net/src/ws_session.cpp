#include "ws_session.h"

#include <algorithm>

#include "haarcast/net/upgrade.h"
#include "session_jobs.h"

namespace haarcast::net {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

// How often a session checks its timeouts and whether Stats are due.
constexpr auto kTick = std::chrono::milliseconds(100);
// Control messages (Welcome, Error, Stats, Pong, SceneInfo) queued behind
// the write in flight. A client that makes more pile up (a Ping burst, or
// not reading) is told so and closed.
constexpr std::size_t kMaxControlQueue = 64;


}  // namespace

WsSession::WsSession(Server::Impl& server, tcp::socket&& socket, Admission::Slot connection, Admission::Slot pending,
                     std::string address)
    : server_(server),
      ws_(std::move(socket)),
      executor_(ws_.get_executor()),
      ticker_(executor_),
      paceTimer_(executor_),
      id_("s" + std::to_string(server.nextSessionId.fetch_add(1))),
      address_(std::move(address)),
      connectionSlot_(std::move(connection)),
      pendingSlot_(std::move(pending)),
      session_(server.options, server.catalog, server.metrics, *this, id_, Clock::now()) {
  if (pendingSlot_) server_.metrics.pending.fetch_add(1);
}

WsSession::~WsSession() {
  if (pendingSlot_) server_.metrics.pending.fetch_sub(1);
  if (sessionSlot_) server_.metrics.sessions.fetch_sub(1);
  if (registered_) {
    std::lock_guard lock(server_.sessionsMutex);
    server_.sessions.erase(this);
  }
}

void WsSession::accept(http::request<http::string_body> request) {
  // The WebSocket stream keeps its own timeouts; the TCP layer's must be off.
  beast::get_lowest_layer(ws_).expires_never();
  configureSessionStream(ws_, server_.options);
  // Registered before the handshake completes, so that a stop() meanwhile
  // waits for this session's close instead of ending the drain without it
  // (onAccept then shuts it down).
  {
    std::lock_guard lock(server_.sessionsMutex);
    server_.sessions.emplace(this, weak_from_this());
    registered_ = true;
  }
  // A newcomer may take this connection's pre-Hello slot while the budget
  // is full (admission.h): then it ends, on its own strand.
  const bool held = endOnEviction(pendingSlot_, shared_from_this());
  ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) { self->onAccept(ec); });
  if (!held) evicted();
}

void WsSession::evicted() {
  if (gone_ || sessionSlot_) return;  // said Hello in the meantime: a session now
  countEviction(server_, pendingSlot_);
  hardClose("no Hello yet, and the pre-Hello budget is full: a connection from another address took its place");
}

void WsSession::shutdown() {
  if (!accepted_) return;  // onAccept sees the server stopping and comes back here
  session_.fail({v1::ERROR_CODE_SHUTTING_DOWN, "the server is shutting down", true}, CloseCode::GoingAway);
}

void WsSession::onAccept(beast::error_code ec) {
  if (ec) {
    if (ec == beast::error::timeout) server_.metrics.addTimeout("ws_handshake");
    server_.log("%s: WebSocket handshake with %s failed: %s", id_.c_str(), address_.c_str(), ec.message().c_str());
    return;
  }
  accepted_ = true;
  server_.log("%s: opened from %s", id_.c_str(), address_.c_str());
  doRead();
  tick();
  if (server_.stopping.load()) shutdown();
}

// ------------------------------------------------------------------ reading

void WsSession::doRead() {
  ws_.async_read(readBuffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) { self->onRead(ec); });
}

void WsSession::onRead(beast::error_code ec) {
  if (ec) {
    if (ec == websocket::error::message_too_big) {
      server_.metrics.addWebSocketViolation("message_too_big");
      server_.metrics.addError(errorLabel(v1::ERROR_CODE_MESSAGE_TOO_LARGE));
      server_.metrics.addCut("message_too_large");
      server_.log("%s: message over %zu bytes: closed (1009)", id_.c_str(), ws_.read_message_max());
    } else if (ec.category() == websocket::make_error_code(websocket::error::bad_opcode).category()) {
      // Beast's WebSocket errors: a frame that breaks RFC 6455 (bad opcode,
      // unmasked, bad UTF-8 text, a close code out of range …), or `closed`.
      if (ec != websocket::error::closed) {
        server_.metrics.addWebSocketViolation("protocol");
        server_.log("%s: WebSocket protocol violation: %s", id_.c_str(), ec.message().c_str());
      }
    } else if (ec != asio::error::operation_aborted) {
      server_.log("%s: read: %s", id_.c_str(), ec.message().c_str());
    }
    finish();
    return;
  }
  const std::string bytes = beast::buffers_to_string(readBuffer_.data());
  readBuffer_.consume(readBuffer_.size());
  if (!closeRequested_) session_.onMessage(bytes, ws_.got_binary(), Clock::now());
  doRead();  // also while closing: the close handshake needs the peer's close frame read
}

// ------------------------------------------------------------------ SessionPort

void WsSession::send(std::string bytes) {
  if (closeRequested_ || gone_) return;
  if (control_.size() >= kMaxControlQueue) {
    // Say why before closing: the queued answers are dropped so the Error
    // goes out next.
    control_.clear();
    session_.fail({v1::ERROR_CODE_OVERLOADED,
                   "over " + std::to_string(kMaxControlQueue) +
                       " messages waiting to be sent: the client sends faster than it reads (a Ping burst?)",
                   true});
    return;
  }
  control_.push_back(Outgoing{std::make_shared<const std::string>(std::move(bytes)), false, 0});
  doWrite();
}

bool WsSession::sendFrame(std::string bytes, std::size_t payloadBytes) {
  if (closeRequested_ || gone_) return false;
  const bool replaced = frameSlot_.has_value();
  frameSlot_ = Outgoing{std::make_shared<const std::string>(std::move(bytes)), true, payloadBytes};
  doWrite();
  return replaced;
}

void WsSession::close(std::string error, CloseCode code, std::string reason) {
  if (closeRequested_ || gone_) return;
  control_.push_back(Outgoing{std::make_shared<const std::string>(std::move(error)), false, 0});
  closeRequested_ = true;
  closeAt_ = Clock::now();
  closeReason_ = websocket::close_reason(static_cast<websocket::close_code>(code), reason);
  frameSlot_.reset();
  paceTimer_.cancel();
  doWrite();
}

void WsSession::armPace(Clock::time_point at) {
  paceTimer_.expires_at(at);
  paceTimer_.async_wait([self = shared_from_this()](beast::error_code ec) {
    if (!ec && !self->gone_) self->session_.onPace(Clock::now());
  });
}

void WsSession::prepare(const SessionConfig& config) { submitPrepare(server_, shared_from_this(), config); }

void WsSession::render(FrameOrder order) { submitFrame(server_, shared_from_this(), std::move(order)); }

std::optional<ProtocolError> WsSession::admit() {
  Admission::Refusal refusal;
  auto slot = server_.admission.take(SlotKind::Session, address_, &refusal);
  if (!slot) {
    server_.metrics.addRefusal(refusal.label);
    return ProtocolError{v1::ERROR_CODE_TOO_MANY_SESSIONS, refusal.reason, true};
  }
  sessionSlot_ = std::move(*slot);
  server_.metrics.sessions.fetch_add(1);
  server_.metrics.sessionsTotal.fetch_add(1);
  if (pendingSlot_) {
    pendingSlot_.release();
    server_.metrics.pending.fetch_sub(1);
  }
  return std::nullopt;
}

void WsSession::tokenRejected() { server_.tokenGuard.failed(address_, Clock::now()); }

void WsSession::log(const std::string& line) { server_.log("%s", line.c_str()); }

// ------------------------------------------------------------------ writing: one in flight

void WsSession::doWrite() {
  if (writing_ || closeStarted_ || gone_) return;
  Outgoing next;
  if (!control_.empty()) {
    next = std::move(control_.front());
    control_.pop_front();
  } else if (frameSlot_) {
    next = std::move(*frameSlot_);
    frameSlot_.reset();
  } else {
    if (closeRequested_) startClose();
    return;
  }
  writing_ = true;
  writeStarted_ = Clock::now();
  ws_.async_write(asio::buffer(*next.bytes), [self = shared_from_this(), next](beast::error_code ec, std::size_t) {
    self->onWrite(ec, next);
  });
}

void WsSession::onWrite(beast::error_code ec, const Outgoing& sent) {
  writing_ = false;
  if (ec) {
    if (ec != asio::error::operation_aborted) server_.log("%s: write: %s", id_.c_str(), ec.message().c_str());
    finish();
    return;
  }
  session_.onSent(sent.isFrame, sent.payloadBytes);
  doWrite();
}

void WsSession::startClose() {
  closeStarted_ = true;
  ws_.async_close(closeReason_, [self = shared_from_this()](beast::error_code) { self->finish(); });
}

// Cuts the connection: pending operations complete with operation_aborted.
void WsSession::hardClose(const char* why) {
  if (gone_) return;
  server_.log("%s: cut: %s", id_.c_str(), why);
  closeRequested_ = true;
  beast::error_code ec;
  beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_both, ec);
  beast::get_lowest_layer(ws_).socket().close(ec);
  finish();
}

// The session is over: stop the timers; it is destroyed when the last
// pending handler lets go of it.
void WsSession::finish() {
  if (gone_) return;
  gone_ = true;
  session_.end();  // and the frame in flight is cancelled at its next tile
  // A build only this session waited for is dropped (queued) or abandoned
  // (running): it does not hold the builder for the next client.
  server_.renderService->withdraw(id_);
  ticker_.cancel();
  paceTimer_.cancel();
  logClosed(server_, id_, session_);
}

// ------------------------------------------------------------------ timers

void WsSession::tick() {
  ticker_.expires_after(kTick);
  ticker_.async_wait([self = shared_from_this()](beast::error_code ec) {
    if (!ec) self->onTick();
  });
}

void WsSession::onTick() {
  if (gone_) return;
  const auto now = Clock::now();
  if (const char* why = watchdogCut(server_, writing_, writeStarted_, closeRequested_, closeAt_, now)) {
    hardClose(why);
    return;
  }
  if (!closeRequested_) session_.onTick(now);
  tick();
}

}  // namespace haarcast::net
