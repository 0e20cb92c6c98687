// The haarcast service on one port (Boost.Asio + Beast):
//
//   GET /                 the browser client (the web root's index.html and its files)
//   GET /haarcast.proto   the wire contract, for the browser client
//   GET /healthz          200 "ok"
//   GET /metrics          Prometheus text (metrics.h)
//   /ws                   WebSocket: one protobuf message per binary message,
//                         ClientMessage in, ServerMessage out (proto/haarcast.proto)
//
// The token (if set) is checked at the upgrade, from `?token=T` or
// `Authorization: Bearer T`: a wrong one gets HTTP 401 and no WebSocket.
// Each session runs on its own strand with one write in flight, a bounded
// queue of control messages and a one-frame slot (latest frame wins). See
// docs/service.md for the protocol, limits and operations.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "haarcast/net/metrics.h"
#include "haarcast/net/protocol.h"
#include "haarcast/net/render_service.h"

namespace haarcast::net {

struct ServerOptions {
  std::string bindAddress = "0.0.0.0";
  std::uint16_t port = 8080;  // 0: any free port (see Server::port())
  std::string token;          // empty: no authentication
  std::filesystem::path webRoot;    // the browser client's files; empty: none served
  std::filesystem::path protoFile;  // served at /haarcast.proto; empty: 404
  Limits limits;
  Defaults defaults;
  double handshakeSeconds = 10.0;   // HTTP request and Hello, each within this
  double idleSeconds = 120.0;       // no client message for this long → TIMEOUT
  double writeStallSeconds = 10.0;  // one write in flight this long → the client is not reading: close
  double statsSeconds = 1.0;        // Stats period
  double drainSeconds = 3.0;        // stop(): the most time sessions get to close cleanly
  int ioThreads = 2;
  RenderService::Options render;
  bool log = true;                  // one line per session event on stderr
  // SIGINT and SIGTERM call stop(). Installed when the Server is built, so a
  // signal that follows the "listening" line is never missed.
  bool handleSignals = false;
};

class Server {
 public:
  // Binds and listens at once; throws std::runtime_error naming the address
  // when it cannot. The renderers come from `builder` (haarcast/gpu/backend.h
  // in `haarcast serve`).
  Server(ServerOptions options, Catalog catalog, RendererBuilder builder);
  ~Server();  // stop() and wait()
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  std::uint16_t port() const;  // the bound port

  // Runs the I/O threads in the background / blocks until stopped and
  // drained (and the render threads have finished).
  void start();
  void run();
  // Graceful shutdown, from any thread (a signal handler's strand included):
  // stop accepting, send Error SHUTTING_DOWN to each session, let writes in
  // flight finish, close; after drainSeconds whatever is left is cut.
  // Idempotent.
  void stop();
  // Joins the background threads (after start()).
  void wait();

  const Metrics& metrics() const;

  struct Impl;  // defined in server.cpp

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace haarcast::net
