// The WebSocket transport of one session: reads messages into its
// RenderSession, writes what it emits (one write in flight; a bounded queue
// of control messages first, then a one-frame slot where the latest frame
// wins), runs the timers (ticks, pacing, write stall, close), closes with a
// code and a reason, and holds the session's slots. Everything runs on the
// socket's strand.
#pragma once

#include <deque>
#include <memory>
#include <optional>
#include <string>

#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include "haarcast/net/render_session.h"
#include "server_impl.h"

namespace haarcast::net {

class WsSession : public std::enable_shared_from_this<WsSession>, private SessionPort {
 public:
  // `pending`: the pre-Hello slot the upgrade took; swapped for a session
  // slot at a valid Hello.
  WsSession(Server::Impl& server, boost::asio::ip::tcp::socket&& socket, Admission::Slot connection,
            Admission::Slot pending, std::string address);
  ~WsSession() override;

  void accept(boost::beast::http::request<boost::beast::http::string_body> request);
  // From Server::stop(), posted to the strand.
  void shutdown();
  const boost::asio::any_io_executor& executor() const { return executor_; }
  // For session_jobs.h: on the strand (renderSession(), gone()) or anywhere (sessionId()).
  RenderSession& renderSession() { return session_; }
  bool gone() const { return gone_; }
  const std::string& sessionId() const { return id_; }

  // For session_jobs.h endOnEviction, on the strand: a newcomer took this
  // connection's pre-Hello slot: close it.
  void evicted();

 private:
  struct Outgoing {
    std::shared_ptr<const std::string> bytes;
    bool isFrame = false;
    std::size_t payloadBytes = 0;
  };

  void onAccept(boost::beast::error_code ec);
  void doRead();
  void onRead(boost::beast::error_code ec);
  void doWrite();
  void onWrite(boost::beast::error_code ec, const Outgoing& sent);
  void startClose();
  void hardClose(const char* why);
  void finish();
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
  boost::beast::websocket::stream<boost::beast::tcp_stream> ws_;
  boost::asio::any_io_executor executor_;  // the strand the socket was accepted on
  boost::asio::steady_timer ticker_, paceTimer_;
  boost::beast::flat_buffer readBuffer_;
  std::string id_, address_;
  Admission::Slot connectionSlot_, pendingSlot_, sessionSlot_;
  bool registered_ = false;  // in server_.sessions (from accept())
  bool accepted_ = false;    // the WebSocket handshake completed (on the strand)
  RenderSession session_;

  bool writing_ = false, closeRequested_ = false, closeStarted_ = false, gone_ = false;
  std::deque<Outgoing> control_;
  std::optional<Outgoing> frameSlot_;
  boost::beast::websocket::close_reason closeReason_;
  Clock::time_point writeStarted_, closeAt_;
};

}  // namespace haarcast::net
