#include "grpc_session.h"

#include <vector>

#include <boost/asio/post.hpp>

#include "grpc_server.h"
#include "haarcast/net/grpc_rules.h"
#include "session_jobs.h"

namespace haarcast::net {
namespace {

namespace asio = boost::asio;

// As ws_session.cpp: how often a session checks its timeouts and Stats, and
// how many control messages may wait behind the write in flight.
constexpr auto kTick = std::chrono::milliseconds(100);
constexpr std::size_t kMaxControlQueue = 64;


grpc::Status status(GrpcCode code, const std::string& message) {
  return {static_cast<grpc::StatusCode>(static_cast<int>(code)), message};
}

// The `authorization` metadata of a call ("" without one). gRPC lower-cases
// metadata keys.
std::string authorizationOf(const grpc::CallbackServerContext& context) {
  const auto& metadata = context.client_metadata();
  const auto it = metadata.find("authorization");
  return it == metadata.end() ? std::string() : std::string(it->second.data(), it->second.size());
}

}  // namespace

GrpcSession::GrpcSession(Server::Impl& server, GrpcServer& registry, grpc::CallbackServerContext* context)
    : server_(server),
      registry_(registry),
      context_(context),
      executor_(asio::make_strand(server.ioc)),
      ticker_(executor_),
      paceTimer_(executor_),
      id_("g" + std::to_string(server.nextSessionId.fetch_add(1))),
      address_(registry.peerGroup(context->peer())),
      session_(server.options, server.catalog, server.metrics, *this, id_, Clock::now()) {}

GrpcSession::~GrpcSession() {
  if (pendingSlot_) server_.metrics.pending.fetch_sub(1);
  if (sessionSlot_) {
    server_.metrics.sessions.fetch_sub(1);
    server_.metrics.grpcSessions.fetch_sub(1);
  }
  if (registered_) registry_.remove(this);
}

grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>* GrpcSession::start() {
  self_ = shared_from_this();
  asio::post(executor_, [self = self_] { self->open(); });
  return this;
}

// The checks of the WebSocket upgrade, then the first read.
void GrpcSession::open() {
  if (finished_) return;  // cancelled before it opened
  if (server_.stopping.load()) {
    server_.metrics.addRefusal("draining");
    finishCall(status(GrpcCode::Unavailable, "the server is shutting down"));
    return;
  }
  if (auto refusal = checkGrpcToken(authorizationOf(*context_), server_.options.token, server_.tokenGuard, address_,
                                    Clock::now())) {
    server_.metrics.addRefusal(refusal->metric);
    if (refusal->code == GrpcCode::Unauthenticated) server_.metrics.addError(errorLabel(v1::ERROR_CODE_UNAUTHORIZED));
    // Through the refusal log, as the upgrade's: a line per address a
    // period and a summary, not a line per guess of a spray.
    server_.logRefusal(address_, "gRPC stream from " + address_ + " refused: " + refusal->message);
    finishCall(status(refusal->code, refusal->message));
    return;
  }
  // The pre-Hello budget, shared with the WebSocket connections.
  Admission::Refusal refusal;
  auto pending = server_.admission.take(SlotKind::Pending, address_, &refusal);
  if (!pending) {
    server_.metrics.addRefusal(refusal.perAddress ? "pending_per_address" : "pending");
    finishCall(status(refusal.perAddress ? GrpcCode::ResourceExhausted : GrpcCode::Unavailable, refusal.reason));
    return;
  }
  pendingSlot_ = std::move(*pending);
  server_.metrics.pending.fetch_add(1);
  registry_.add(this, weak_from_this());
  registered_ = true;
  // A newcomer from another address may take this stream's pre-Hello slot
  // while the budget is full (admission.h): then it ends, as a WebSocket
  // connection does, on its own executor.
  const bool held = endOnEviction(pendingSlot_, shared_from_this());
  if (!held) {
    evicted();
    return;
  }
  // No log line yet: a stream costs one only once its Hello is valid
  // (admit), so that streams opened and reset by the thousand cannot flood
  // the log.
  StartRead(&in_);
  tick();
  // stop() may have taken its list of sessions just before this one joined.
  if (server_.stopping.load()) shutdown();
}

void GrpcSession::evicted() {
  if (finished_ || sessionSlot_) return;  // said Hello in the meantime: a session now
  countEviction(server_, pendingSlot_);
  server_.logRefusal(address_, id_ + ": gRPC stream from " + address_ +
                                   " cut: no Hello yet, and the pre-Hello budget is full");
  finishCall(status(GrpcCode::ResourceExhausted,
                    "no Hello yet, and the pre-Hello budget is full: a connection from another address took its place"));
}

void GrpcSession::shutdown() {
  if (!registered_ || finished_) return;
  session_.fail({v1::ERROR_CODE_SHUTTING_DOWN, "the server is shutting down", true}, CloseCode::GoingAway);
}

// ------------------------------------------------------------------ reactions (gRPC's threads)

void GrpcSession::OnReadDone(bool ok) {
  if (!ok) {
    asio::post(executor_, [self = shared_from_this()] { self->onReadEnded(); });
    return;
  }
  std::vector<grpc::Slice> slices;
  std::string bytes;
  if (in_.Dump(&slices).ok()) {
    bytes.reserve(in_.Length());
    for (const auto& s : slices) bytes.append(reinterpret_cast<const char*>(s.begin()), s.size());
  }
  in_.Clear();
  asio::post(executor_, [self = shared_from_this(), bytes = std::move(bytes)]() mutable {
    self->onRead(std::move(bytes));
  });
}

void GrpcSession::OnWriteDone(bool ok) {
  asio::post(executor_, [self = shared_from_this(), ok] { self->onWritten(ok); });
}

void GrpcSession::OnCancel() {
  asio::post(executor_, [self = shared_from_this()] {
    if (self->finished_) return;
    if (self->sessionSlot_) self->server_.log("%s: cancelled (the client went away, or its deadline passed)", self->id_.c_str());
    self->finishCall(grpc::Status::CANCELLED);
  });
}

// gRPC is done with the reactor: its reference goes to the strand, where
// the last handler holding the session lets go of it.
void GrpcSession::OnDone() {
  asio::post(executor_, [self = std::move(self_)] {});
}

// ------------------------------------------------------------------ reading (the strand)

void GrpcSession::onRead(std::string bytes) {
  if (finished_) return;
  if (!closeRequested_) session_.onMessage(bytes, true, Clock::now());
  // One read in flight, and the next only once this one is handled: a
  // client that floods meets HTTP/2 flow control. After a fatal Error
  // nothing more is read.
  if (!finished_ && !closeRequested_) StartRead(&in_);
}

// The client half-closed its side (it sends no more), or the call broke
// (then OnCancel comes too): what is queued goes out, then Finish(OK).
void GrpcSession::onReadEnded() {
  if (finished_ || closeRequested_) return;
  if (sessionSlot_) server_.log("%s: the client ended its stream", id_.c_str());
  session_.end();
  closeRequested_ = true;
  closeAt_ = Clock::now();
  closeStatus_ = grpc::Status::OK;
  frameSlot_.reset();
  paceTimer_.cancel();
  doWrite();
}

// ------------------------------------------------------------------ SessionPort

void GrpcSession::send(std::string bytes) {
  if (closeRequested_ || gone_) return;
  if (control_.size() >= kMaxControlQueue) {
    control_.clear();
    session_.fail({v1::ERROR_CODE_OVERLOADED,
                   "over " + std::to_string(kMaxControlQueue) +
                       " messages waiting to be sent: the client sends faster than it reads (a Ping burst?)",
                   true});
    return;
  }
  control_.push_back(Outgoing{std::move(bytes), false, 0});
  doWrite();
}

bool GrpcSession::sendFrame(std::string bytes, std::size_t payloadBytes) {
  if (closeRequested_ || gone_) return false;
  const bool replaced = frameSlot_.has_value();
  frameSlot_ = Outgoing{std::move(bytes), true, payloadBytes};
  doWrite();
  return replaced;
}

void GrpcSession::close(std::string error, CloseCode /*code: the status carries it*/, std::string reason) {
  if (closeRequested_ || gone_) return;
  v1::ServerMessage parsed;
  const v1::ErrorCode code = parsed.ParseFromString(error) ? parsed.error().code() : v1::ERROR_CODE_UNSPECIFIED;
  closeStatus_ = status(grpcCodeFor(code), reason);
  control_.push_back(Outgoing{std::move(error), false, 0});
  closeRequested_ = true;
  closeAt_ = Clock::now();
  frameSlot_.reset();
  paceTimer_.cancel();
  doWrite();
}

void GrpcSession::armPace(Clock::time_point at) {
  paceTimer_.expires_at(at);
  paceTimer_.async_wait([self = shared_from_this()](boost::system::error_code ec) {
    if (!ec && !self->gone_) self->session_.onPace(Clock::now());
  });
}

void GrpcSession::prepare(const SessionConfig& config) { submitPrepare(server_, shared_from_this(), config); }

void GrpcSession::render(FrameOrder order) { submitFrame(server_, shared_from_this(), std::move(order)); }

std::optional<ProtocolError> GrpcSession::admit() {
  Admission::Refusal refusal;
  auto slot = server_.admission.take(SlotKind::Session, address_, &refusal);
  if (!slot) {
    server_.metrics.addRefusal(refusal.perAddress ? "sessions_per_address" : "sessions");
    return ProtocolError{v1::ERROR_CODE_TOO_MANY_SESSIONS, refusal.reason, true};
  }
  sessionSlot_ = std::move(*slot);
  server_.log("%s: opened from %s (gRPC)", id_.c_str(), address_.c_str());
  server_.metrics.sessions.fetch_add(1);
  server_.metrics.sessionsTotal.fetch_add(1);
  server_.metrics.grpcSessions.fetch_add(1);
  server_.metrics.grpcSessionsTotal.fetch_add(1);
  if (pendingSlot_) {
    pendingSlot_.release();
    server_.metrics.pending.fetch_sub(1);
  }
  return std::nullopt;
}

void GrpcSession::tokenRejected() { server_.tokenGuard.failed(address_, Clock::now()); }

void GrpcSession::log(const std::string& line) { server_.log("%s", line.c_str()); }

// ------------------------------------------------------------------ writing: one in flight

void GrpcSession::doWrite() {
  if (writing_ || finished_) return;
  Outgoing next;
  if (!control_.empty()) {
    next = std::move(control_.front());
    control_.pop_front();
  } else if (frameSlot_) {
    next = std::move(*frameSlot_);
    frameSlot_.reset();
  } else {
    if (closeRequested_) finishCall(closeStatus_);
    return;
  }
  // The serialised message becomes the slice as it is: gRPC frees it when
  // it has been sent.
  auto* bytes = new std::string(std::move(next.bytes));
  grpc::Slice slice(bytes->data(), bytes->size(), [](void* p) { delete static_cast<std::string*>(p); }, bytes);
  out_ = grpc::ByteBuffer(&slice, 1);
  inFlight_ = Outgoing{{}, next.isFrame, next.payloadBytes};
  writing_ = true;
  writeStarted_ = Clock::now();
  StartWrite(&out_);
}

void GrpcSession::onWritten(bool ok) {
  writing_ = false;
  const Outgoing sent = inFlight_.value_or(Outgoing{});
  inFlight_.reset();
  out_.Clear();
  if (finished_) return;
  if (!ok) {
    server_.log("%s: write failed: the stream is gone", id_.c_str());
    finishCall(grpc::Status::CANCELLED);
    return;
  }
  session_.onSent(sent.isFrame, sent.payloadBytes);
  if (sent.isFrame) {
    server_.metrics.grpcFramesTotal.fetch_add(1);
    server_.metrics.grpcBytesTotal.fetch_add(sent.payloadBytes);
  }
  doWrite();
}

// The one Finish of the call, and the session's end: timers stop, the
// frame in flight is cancelled, a build only it waited for is withdrawn.
// gRPC then calls OnDone, which lets the session go.
void GrpcSession::finishCall(grpc::Status finalStatus) {
  if (finished_) return;
  finished_ = true;
  gone_ = true;
  Finish(std::move(finalStatus));
  session_.end();
  ticker_.cancel();
  paceTimer_.cancel();
  if (!registered_) return;  // refused before it opened: nothing was started
  server_.renderService->withdraw(id_);
  if (sessionSlot_) logClosed(server_, id_, session_);  // the line that "opened" began
}

// Cuts the call: operations in flight fail, the client sees CANCELLED.
void GrpcSession::hardClose(const char* why) {
  if (finished_) return;
  server_.log("%s: cut: %s", id_.c_str(), why);
  context_->TryCancel();
  finishCall(grpc::Status(grpc::StatusCode::CANCELLED, why));
}

// ------------------------------------------------------------------ timers

void GrpcSession::tick() {
  ticker_.expires_after(kTick);
  ticker_.async_wait([self = shared_from_this()](boost::system::error_code ec) {
    if (!ec) self->onTick();
  });
}

void GrpcSession::onTick() {
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
