// The gRPC transport of one session: the reactor of one
// haarcast.v1.Render/Session stream, carrying a RenderSession as
// ws_session.h carries one on a WebSocket. The messages travel as raw bytes
// (the service's raw callback method): each one the client sends goes to
// RenderSession::onMessage exactly as a WebSocket message does, so the size
// limit, the parser and every protocol rule are the same code, and each one
// the session emits is written as it was serialised.
//
// gRPC calls the reactions (OnReadDone, OnWriteDone, OnCancel, OnDone) on
// its own threads; each only posts to the session's strand, where every
// stream operation (StartRead, StartWrite, Finish) and every RenderSession
// call is made. So no lock guards the stream, and a reaction that gRPC runs
// inline inside a stream operation cannot deadlock.
//
// Writes: one in flight; a bounded queue of control messages first, then a
// one-frame slot where the latest frame wins (HTTP/2 flow control stalls
// the write of a client that stops reading: it is cut after
// writeStallSeconds). Reads: the next one starts once the strand has handled
// the last, so a client that floods is held back by flow control too.
// The end: a fatal Error is the last message, then Finish with the status
// grpcCodeFor() names; a client that half-closes gets Finish(OK).
#pragma once

#include <deque>
#include <memory>
#include <optional>
#include <string>

#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <grpcpp/grpcpp.h>

#include "haarcast/net/render_session.h"
#include "server_impl.h"

namespace haarcast::net {

class GrpcServer;

class GrpcSession : public grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>,
                    public std::enable_shared_from_this<GrpcSession>,
                    private SessionPort {
 public:
  GrpcSession(Server::Impl& server, GrpcServer& registry, grpc::CallbackServerContext* context);
  ~GrpcSession() override;

  // The reactor to hand to gRPC: keeps this session alive until OnDone and
  // posts the stream's start (token, pre-Hello slot, first read) to the strand.
  grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>* start();
  // From Server::stop(), posted to the strand.
  void shutdown();

  // For session_jobs.h: on the strand (renderSession(), gone()) or anywhere.
  const boost::asio::any_io_executor& executor() const { return executor_; }
  RenderSession& renderSession() { return session_; }
  bool gone() const { return gone_; }
  const std::string& sessionId() const { return id_; }
  // For session_jobs.h endOnEviction, on the strand: a newcomer took this
  // stream's pre-Hello slot: end it.
  void evicted();

 private:
  struct Outgoing {
    std::string bytes;
    bool isFrame = false;
    std::size_t payloadBytes = 0;
  };

  // Reactions (gRPC's threads).
  void OnReadDone(bool ok) override;
  void OnWriteDone(bool ok) override;
  void OnCancel() override;
  void OnDone() override;

  // The strand.
  void open();
  void onRead(std::string bytes);
  void onReadEnded();
  void doWrite();
  void onWritten(bool ok);
  void finishCall(grpc::Status status);
  void hardClose(const char* why);
  void tick();
  void onTick();

  // SessionPort
  void send(std::string bytes) override;
  bool sendFrame(std::string bytes, std::size_t payloadBytes) override;
  std::size_t backlog() const override { return control_.size(); }
  void close(std::string error, CloseCode code, std::string reason) override;
  void armPace(Clock::time_point at) override;
  void prepare(const SessionConfig& config) override;
  void render(FrameOrder order) override;
  std::optional<ProtocolError> admit() override;
  void tokenRejected() override;
  void log(const std::string& line) override;

  Server::Impl& server_;
  GrpcServer& registry_;
  grpc::CallbackServerContext* const context_;
  boost::asio::any_io_executor executor_;  // a strand of the Server's io_context
  boost::asio::steady_timer ticker_, paceTimer_;
  std::string id_, address_;
  Admission::Slot pendingSlot_, sessionSlot_;
  bool registered_ = false;
  RenderSession session_;
  std::shared_ptr<GrpcSession> self_;  // gRPC's reference: from start() to OnDone

  // Reads and writes: the buffers gRPC fills and sends (one of each in flight).
  grpc::ByteBuffer in_, out_;
  std::optional<Outgoing> inFlight_;
  bool writing_ = false, closeRequested_ = false, finished_ = false, gone_ = false;
  std::deque<Outgoing> control_;
  std::optional<Outgoing> frameSlot_;
  grpc::Status closeStatus_;
  Clock::time_point writeStarted_, closeAt_;
};

}  // namespace haarcast::net
