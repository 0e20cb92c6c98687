// What the listener, the HTTP sessions and the WebSocket sessions share: the
// server's options, catalogue, metrics, slots and token guard, the session
// registry (for stop()), the log, the io_context and the render service.
#pragma once

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio.hpp>

#include "accept_loop.h"
#include "haarcast/net/access.h"
#include "haarcast/net/refusal_log.h"
#include "haarcast/net/server.h"
#include "haarcast/net/static_files.h"

namespace haarcast::net {

class WsSession;
class GrpcServer;  // grpc_server.h

struct Server::Impl {
  ServerOptions options;
  Catalog catalog;
  std::optional<WebRoot> webRoot;  // the served client, when options.webRoot is set
  Metrics metrics;
  Admission admission;
  TokenGuard tokenGuard;
  RefusalLog refusalLog;
  std::mutex logMutex;
  std::mutex sessionsMutex;
  std::map<const WsSession*, std::weak_ptr<WsSession>> sessions;  // every WebSocket, before and after Hello
  std::atomic<bool> stopping{false};
  std::atomic<std::uint64_t> nextSessionId{1};
  std::vector<std::thread> threads;
  // The gRPC listener (options.grpcPort): before the io_context, because
  // its sessions' destructors (run when the io_context drops their
  // handlers) take it out of its registry.
  std::unique_ptr<GrpcServer> grpc;

  // Declared after everything sessions touch in their destructors, so that
  // the handlers the io_context destroys find them alive; the render service
  // after the io_context, so its threads (which post into it) stop first.
  boost::asio::io_context ioc;
  AcceptLoop accept;  // the WebSocket and HTTP port
  std::optional<boost::asio::signal_set> signals;
  boost::asio::steady_timer drainTimer;
  boost::asio::steady_timer refusalSummaryTimer;
  Clock::time_point drainDeadline;
  // When stop() was first called: the render service's stop grace counts
  // from here, so SIGTERM's exit is bounded whatever the drain takes.
  Clock::time_point stopRequested;
  std::unique_ptr<RenderService> renderService;

  Impl(ServerOptions o, Catalog c, AbandonableRendererBuilder builder);
  ~Impl();

  void log(const char* format, ...) __attribute__((format(printf, 2, 3)));
  RenderService::Options withLog(RenderService::Options o);
  // A refused request from `address`: `line` is written if it is the
  // address's first this period (refusal_log.h); "" counts it only.
  void logRefusal(const std::string& address, const std::string& line);
  // Every RefusalLog::kPeriodSeconds: the summary line, when one is due.
  void scheduleRefusalSummary();
  // A connection accepted on the WebSocket port: its slot, then HTTP.
  void onConnection(boost::asio::ip::tcp::socket socket, std::string address);
  void stop();
  void watchDrain();
  std::size_t sessionCount();
  bool atCapacity() const;
  std::optional<std::string> notReadyReason() const;
  // Why the process should be restarted (/healthz 503): a listener that no
  // longer accepts (GrpcServer::listenerProblem); nullopt when healthy.
  std::optional<std::string> unhealthyReason() const;
  // The render service stopped, its stop grace counted from stop(), and the
  // threads it left behind logged. After the I/O threads have been joined.
  void stopRenderService();
  // /metrics: the render service's gauges copied into `metrics`, then the text.
  std::string metricsText();
};

}  // namespace haarcast::net
