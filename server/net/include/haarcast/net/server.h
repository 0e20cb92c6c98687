// The haarcast service on one port (Boost.Asio + Beast):
//
//   GET /                 the browser client (the files the web root's
//                         served_files.txt names, index.html first)
//   GET /haarcast.proto   the wire contract, for the browser client
//   GET /healthz          200 "ok" while the process serves (liveness)
//   GET /readyz           200 "ready", or 503 at capacity, draining, or while
//                         the default backend's device is unhealthy (readiness)
//   GET /metrics          Prometheus text (metrics.h)
//   /ws                   WebSocket: one protobuf message per binary message,
//                         ClientMessage in, ServerMessage out (proto/haarcast.proto)
//
// and, with ServerOptions::grpcPort, a gRPC port: the same session as the
// bidirectional stream haarcast.v1.Render/Session, the standard health
// service and server reflection (grpc_server.h).
//
// Before any route but /healthz and /readyz: the Host (host_check.h: an IP
// literal, localhost or --allow-host, else 421). At the upgrade: the Origin (access.h: same host or --allow-origin, else
// 403), the token if set (`?token=T` or `Authorization: Bearer T`, else
// 401; repeated wrong tokens from one address: 429 for a while) and the
// pre-Hello budget. A session counts toward the session budget from its
// valid Hello. The pieces, as in Beast's examples:
//
//   listener.cpp      accept (with back-off), per-address connection slots,
//                     start and stop (drain)
//   http_session.cpp  HTTP requests and the upgrade's checks
//   ws_session.cpp    the WebSocket transport: reads, the write queue
//                     (one in flight, bounded control queue, one frame slot),
//                     timers, close
//   render_session.h  the application: Hello, settings, scene, poses, pacing
//
// docs/service.md has the protocol, limits and operations.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "haarcast/net/access.h"
#include "haarcast/net/metrics.h"
#include "haarcast/net/protocol.h"
#include "haarcast/net/render_service.h"

namespace haarcast::net {

struct ServerOptions {
  // Loopback by default: a server reachable from other machines is an
  // operator's choice (--bind 0.0.0.0), and should come with a token.
  std::string bindAddress = "127.0.0.1";
  std::uint16_t port = 8080;  // 0: any free port (see Server::port())
  // The gRPC listener (the Render service, health and reflection) on the
  // same address: unset = none; 0 = any free port (see Server::grpcPort()).
  std::optional<std::uint16_t> grpcPort;
  std::string token;          // empty: no authentication
  // Origins besides the serving host whose pages may open a WebSocket
  // ("https://app.example.com"); see originAllowed().
  std::vector<std::string> allowOrigins;
  // Host names besides IP literals and "localhost" that requests may carry
  // (--allow-host; host_check.h): the names clients reach the server by.
  std::vector<std::string> allowHosts;
  std::filesystem::path webRoot;    // the browser client's files; empty: none served
  std::filesystem::path protoFile;  // served at /haarcast.proto; empty: 404
  Limits limits;
  Defaults defaults;
  Admission::Limits admission;      // sessions (--max-sessions), per address, pre-Hello
  TokenGuard::Options tokenGuard;
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

// The start-up warning for a server other machines can reach without a
// token, or nullopt.
std::optional<std::string> exposureWarning(const ServerOptions& options);

class Server {
 public:
  // Binds and listens at once; throws std::runtime_error naming the address
  // when it cannot. The renderers come from `builder` (the app layer's
  // backend factory in `haarcast serve`).
  Server(ServerOptions options, Catalog catalog, RendererBuilder builder);
  // A builder that stops early once nobody waits for its build (the
  // session closed, or the server stops): what lets SIGTERM end a running
  // build at its next precompute step. Its progress reaches the waiting
  // clients as BuildProgress messages.
  Server(ServerOptions options, Catalog catalog, AbandonableRendererBuilder builder);
  ~Server();  // stop() and wait()
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  std::uint16_t port() const;  // the bound port
  std::uint16_t grpcPort() const;  // the bound gRPC port; 0 without one

  // Runs the I/O threads in the background / blocks until stopped and
  // drained, and the render threads have finished or, past the render
  // service's stop grace (counted from stop()), been left behind: each is
  // logged with its stage (renderThreadsLeft()).
  void start();
  void run();
  // Graceful shutdown, from any thread (a signal handler's strand included):
  // /readyz turns 503, upgrades are refused, each session gets Error
  // SHUTTING_DOWN, writes in flight finish, sessions close; after
  // drainSeconds whatever is left is cut and the port closes. Idempotent.
  void stop();
  // Joins the background threads (after start()).
  void wait();

  // True when a load balancer should send no new clients here (/readyz 503,
  // gRPC health NOT_SERVING): the session budget is full, the render
  // service is at its pixel budget (RenderService::atPixelBudget: a job
  // waits for pixels), the server is draining, or a device of the default
  // backend is unhealthy (a frame abandoned on it has not returned: the
  // sessions that ask for nothing in particular would get errors).
  bool atCapacity() const;
  // Why atCapacity(), as /readyz says it ("at capacity", "draining",
  // "device unhealthy: …"); nullopt when ready.
  std::optional<std::string> notReadyReason() const;

  // Render threads left behind, inside renders that never returned: after
  // run(), the process should leave without destructors (they could wait on
  // those threads inside a driver): `haarcast serve` does.
  std::size_t renderThreadsLeft() const;

  const Metrics& metrics() const;

  struct Impl;  // server_impl.h

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace haarcast::net
