// The gRPC listener beside the WebSocket one (ServerOptions::grpcPort, on
// the same bind address): the Render service, whose bidirectional stream
// carries one RenderSession (grpc_session.h); the standard health service
// grpc.health.v1.Health, SERVING while /readyz would answer ready; and
// server reflection, so that grpcurl and friends list and describe the
// service. gRPC listens on nothing: the port is the front's (grpc_front.h),
// which accepts each connection, checks its HTTP/2 frame headers, and hands
// it to gRPC. The Server builds it after its own port and stops it at the
// end of its drain (listener.cpp).
//
// Threads: gRPC calls the service and the reactors on its own threads; a
// reactor only posts to its session's strand on the Server's io_context,
// where everything else happens. The health status is kept by a thread of
// its own, and the final Shutdown runs on another (it blocks until every
// stream has finished, and the streams finish on the I/O threads).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>  // before Asio: its awaitable.hpp uses std::exchange

#include "server_impl.h"

namespace haarcast::net {

class GrpcSession;

class GrpcServer {
 public:
  // Listens and starts serving; throws std::runtime_error naming the
  // address when it cannot (or, built without HAARCAST_GRPC, always).
  explicit GrpcServer(Server::Impl& server);
  ~GrpcServer();  // join()
  GrpcServer(const GrpcServer&) = delete;
  GrpcServer& operator=(const GrpcServer&) = delete;

  std::uint16_t port() const;
  // The client group of a stream's peer (context->peer()): the address
  // the front accepted its connection from.
  std::string peerGroup(std::string_view peer) const;
  // Why the port is dead, once a few probes in a row went unanswered
  // (listener_probe.h); nullopt while it accepts. /healthz answers 503 with
  // it, and gRPC health says NOT_SERVING.
  std::optional<std::string> listenerProblem() const;
  // Streams open now (from their first reaction until destroyed): the drain
  // waits for them as for WebSocket sessions.
  std::size_t sessionCount() const;
  // Server::stop(): health NOT_SERVING at once, and every session gets
  // Error SHUTTING_DOWN (new streams are refused with UNAVAILABLE).
  void stopSessions();
  // The drain is over: on a thread of its own, gRPC's Shutdown (streams
  // still open are cancelled after a short deadline), then `then`.
  // A second call runs `then` at once.
  void shutdownThen(std::function<void()> then);
  // Waits for the shutdown; shuts down now if it never began (a Server
  // destroyed without its I/O threads running: the io_context is run here
  // meanwhile, so that the streams can finish). Idempotent.
  void join();

  // The registry of open streams, for stopSessions() and sessionCount().
  void add(const GrpcSession* session, std::weak_ptr<GrpcSession> weak);
  void remove(const GrpcSession* session);

  struct State;

 private:
  std::unique_ptr<State> state_;
};

}  // namespace haarcast::net
