// The Server: listening, accepting (per-address connection slots, back-off
// when file descriptors run out), start, stop and drain.
#include <csignal>
#include <cstdarg>
#include <cstdio>

#include <boost/beast/core.hpp>

#include "grpc_server.h"
#include "http_session.h"
#include "server_impl.h"
#include "ws_session.h"

namespace haarcast::net {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
using tcp = asio::ip::tcp;

// How often the drain checks whether every session has closed.
constexpr auto kDrainPoll = std::chrono::milliseconds(20);
// Past drainSeconds, the margin for the cut sessions' handlers to run.
constexpr double kDrainMarginSeconds = 0.5;

Admission::Limits checkedAdmission(Admission::Limits l) {
  const std::pair<const char*, int> all[] = {{"sessions", l.sessions},
                                             {"sessions per address", l.sessionsPerAddress},
                                             {"connections per address", l.connectionsPerAddress},
                                             {"pending", l.pending},
                                             {"pending per address", l.pendingPerAddress}};
  for (const auto& [name, value] : all) {
    if (value < 1) throw std::invalid_argument(std::string("server limit ") + name + " must be at least 1 (got " + std::to_string(value) + ")");
  }
  if (l.sessionReserve < -1) {
    throw std::invalid_argument("server limit session reserve must be -1 (automatic) or at least 0 (got " +
                                std::to_string(l.sessionReserve) + ")");
  }
  return l;
}

}  // namespace

// The render service's log lines go to the server's log.
RenderService::Options Server::Impl::withLog(RenderService::Options o) {
  if (!o.log) o.log = [this](const std::string& line) { log("%s", line.c_str()); };
  return o;
}

std::optional<std::string> exposureWarning(const ServerOptions& options) {
  if (!options.token.empty() || isLoopbackAddress(options.bindAddress)) return std::nullopt;
  return "WARNING: listening on " + options.bindAddress +
         " without a token: anyone who can reach this port can open sessions (set --token or $HAARCAST_TOKEN, "
         "or --bind 127.0.0.1)";
}

Server::Impl::Impl(ServerOptions o, Catalog c, AbandonableRendererBuilder builder)
    : options(std::move(o)),
      catalog(std::move(c)),
      admission(checkedAdmission(options.admission)),
      tokenGuard(options.tokenGuard),
      ioc(std::max(1, options.ioThreads)),
      accept(ioc, "", [this](const std::string& line) { log("%s", line.c_str()); }),
      drainTimer(ioc),
      refusalSummaryTimer(ioc),
      renderService(std::make_unique<RenderService>(std::move(builder), withLog(options.render), metrics)) {
  if (!options.webRoot.empty()) webRoot = WebRoot::load(options.webRoot);
  metrics.sessionCapacity.store(options.admission.sessions);
}

// The gRPC server shuts down (GrpcServer::join) before the io_context its
// sessions post to is destroyed.
Server::Impl::~Impl() {
  if (grpc) grpc->join();
}

void Server::Impl::log(const char* format, ...) {
  if (!options.log) return;
  std::lock_guard lock(logMutex);
  std::va_list args;
  va_start(args, format);
  std::fputs("[serve] ", stderr);
  std::vfprintf(stderr, format, args);
  std::fputc('\n', stderr);
  va_end(args);
}

void Server::Impl::logRefusal(const std::string& address, const std::string& line) {
  if (refusalLog.note(address, Clock::now()) && !line.empty()) log("%s", line.c_str());
}

void Server::Impl::scheduleRefusalSummary() {
  refusalSummaryTimer.expires_after(toDuration(RefusalLog::kPeriodSeconds));
  refusalSummaryTimer.async_wait([this](beast::error_code ec) {
    if (ec || stopping.load()) return;
    if (const auto line = refusalLog.summary(Clock::now())) log("%s", line->c_str());
    scheduleRefusalSummary();
  });
}

void Server::Impl::onConnection(tcp::socket socket, std::string address) {
  Admission::Refusal refusal;
  if (auto slot = admission.take(SlotKind::Connection, address, &refusal)) {
    // Frames are small writes answered by small pose messages: without
    // this, Nagle's algorithm holds a frame's last segment until the
    // client's delayed ACK (40 ms on Linux), a stall on every frame.
    beast::error_code ignored;
    socket.set_option(tcp::no_delay(true), ignored);
    std::make_shared<HttpSession>(*this, std::move(socket), std::move(*slot), address)->run();
  } else {
    // Closed unanswered: a flood from one address costs it a descriptor
    // for an instant, not a session's worth of buffers.
    metrics.addRefusal(refusal.label);
    beast::error_code ignored;
    socket.close(ignored);
  }
}

std::size_t Server::Impl::sessionCount() {
  std::lock_guard lock(sessionsMutex);
  return sessions.size() + (grpc ? grpc->sessionCount() : 0);
}

bool Server::Impl::atCapacity() const { return notReadyReason().has_value(); }

std::optional<std::string> Server::Impl::notReadyReason() const {
  if (stopping.load()) return "draining";
  if (admission.fullForNewAddress() || renderService->atPixelBudget()) return "at capacity";
  // The default backend's device: a new session that asks for nothing in
  // particular renders there. Another backend's unhealthy device fails only
  // the sessions that chose it (their frames name it), so it alone does not
  // take the server out of rotation.
  const std::string_view backend = backendName(options.defaults.backend);
  for (const DeviceStatus& d : renderService->devices()) {
    if (!d.healthy && d.backend == backend) return "device unhealthy: " + d.device + " (" + d.backend + "): " + d.reason;
  }
  return std::nullopt;
}

std::optional<std::string> Server::Impl::unhealthyReason() const {
  return grpc ? grpc->listenerProblem() : std::nullopt;
}

std::string Server::Impl::metricsText() {
  metrics.pixelsInFlight.store(renderService->pixelsInFlight());
  metrics.pixelBudget.store(options.render.serverPixelBudget);
  metrics.queuedBuilds.store(renderService->queuedBuilds());
  metrics.maxQueuedBuilds.store(options.render.maxQueuedBuilds);
  metrics.renderThreadsStuck.store(renderService->stuckRenders().size());
  metrics.frameDeadlineSeconds.store(options.render.frameDeadlineSeconds);
  std::vector<Metrics::DeviceHealth> devices;
  for (const DeviceStatus& d : renderService->devices()) devices.push_back({d.backend, d.device, d.healthy});
  metrics.setDevices(std::move(devices));
  return metrics.prometheusText();
}

void Server::Impl::stopRenderService() {
  const auto grace = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options.render.stopGraceSeconds));
  // Not stopped (a Server destroyed without stop()): the grace counts from now.
  renderService->stop((stopping.load() ? stopRequested : Clock::now()) + grace);
  for (const StuckRender& r : renderService->stuckRenders()) {
    if (r.device.empty()) {
      log("a render service thread is still busy (%s): exiting without it", r.stage.c_str());
    } else {
      log("a render thread is still rendering after %.1f s, in stage %s on device %s (%s): exiting without it",
          r.seconds, r.stage.c_str(), r.device.c_str(), r.backend.c_str());
    }
  }
}

void Server::Impl::stop() {
  const auto now = Clock::now();
  if (stopping.exchange(true)) return;
  stopRequested = now;
  metrics.draining.store(true);
  log("stopping: draining %zu sessions", sessionCount());
  std::vector<std::shared_ptr<WsSession>> open;
  {
    std::lock_guard lock(sessionsMutex);
    for (auto& [ptr, weak] : sessions) {
      if (auto s = weak.lock()) open.push_back(std::move(s));
    }
  }
  // Outside the lock: a session's destructor takes it.
  for (auto& s : open) asio::post(s->executor(), [s] { s->shutdown(); });
  open.clear();
  if (grpc) grpc->stopSessions();
  asio::post(ioc, [this] {
    if (signals) signals->cancel();
    drainDeadline = Clock::now() + toDuration(options.drainSeconds + kDrainMarginSeconds);
    watchDrain();
  });
}

// Stops the io_context once every session has closed (HTTP keep-alive
// connections are not waited for), or at the drain deadline. The port stays
// open meanwhile, so that /readyz answers 503 to the load balancer and
// upgrades get a 503 rather than a refused connection.
void Server::Impl::watchDrain() {
  if (sessionCount() == 0 || Clock::now() >= drainDeadline) {
    const std::size_t left = sessionCount();
    for (std::size_t i = 0; i < left; ++i) metrics.addCut("drain_deadline");
    log("stopped (%zu sessions cut)", left);
    auto closeAndStop = [this] {
      asio::post(accept.executor(), [this] {
        refusalSummaryTimer.cancel();
        accept.close();
        ioc.stop();
      });
    };
    // The gRPC server's shutdown blocks until its streams have finished,
    // which they do on the I/O threads: it runs on a thread of its own and
    // stops the io_context after.
    if (grpc) {
      grpc->shutdownThen(std::move(closeAndStop));
    } else {
      closeAndStop();
    }
    return;
  }
  drainTimer.expires_after(kDrainPoll);
  drainTimer.async_wait([this](beast::error_code ec) {
    if (!ec) watchDrain();
  });
}

Server::Server(ServerOptions options, Catalog catalog, RendererBuilder builder)
    : Server(std::move(options), std::move(catalog), asAbandonable(std::move(builder))) {}

Server::Server(ServerOptions options, Catalog catalog, AbandonableRendererBuilder builder)
    : impl_(std::make_shared<Impl>(std::move(options), std::move(catalog), std::move(builder))) {
  if (impl_->catalog.scenes.empty()) throw std::invalid_argument("the server needs at least one scene");
  if (impl_->catalog.backends.empty()) throw std::invalid_argument("the server needs at least one enabled backend");
  if (const auto warning = exposureWarning(impl_->options)) impl_->log("%s", warning->c_str());
  if (impl_->options.handleSignals) {
    impl_->signals.emplace(impl_->ioc, SIGINT, SIGTERM);
    impl_->signals->async_wait([impl = impl_.get()](beast::error_code ec, int signal) {
      if (ec) return;
      impl->log("signal %d", signal);
      impl->stop();
    });
  }
  impl_->accept.listen(impl_->options.bindAddress, impl_->options.port);
  impl_->accept.start([impl = impl_.get()](tcp::socket socket, std::string address) {
    impl->onConnection(std::move(socket), std::move(address));
  });
  impl_->scheduleRefusalSummary();
  if (impl_->options.grpcPort) impl_->grpc = std::make_unique<GrpcServer>(*impl_);
}

Server::~Server() {
  stop();
  wait();
  impl_->stopRenderService();
}

std::uint16_t Server::port() const { return impl_->accept.port(); }

std::uint16_t Server::grpcPort() const { return impl_->grpc ? impl_->grpc->port() : 0; }

void Server::start() {
  for (int i = 0; i < std::max(1, impl_->options.ioThreads); ++i) {
    impl_->threads.emplace_back([impl = impl_.get()] { impl->ioc.run(); });
  }
}

void Server::run() {
  for (int i = 1; i < std::max(1, impl_->options.ioThreads); ++i) {
    impl_->threads.emplace_back([impl = impl_.get()] { impl->ioc.run(); });
  }
  impl_->ioc.run();
  wait();
  impl_->stopRenderService();
}

void Server::stop() { impl_->stop(); }

void Server::wait() {
  for (auto& t : impl_->threads) {
    if (t.joinable()) t.join();
  }
  impl_->threads.clear();
  if (impl_->grpc) impl_->grpc->join();
}

bool Server::atCapacity() const { return impl_->atCapacity(); }

std::optional<std::string> Server::notReadyReason() const { return impl_->notReadyReason(); }

std::size_t Server::renderThreadsLeft() const { return impl_->renderService->stuckRenders().size(); }

const Metrics& Server::metrics() const { return impl_->metrics; }

}  // namespace haarcast::net
