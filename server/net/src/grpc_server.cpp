#include "grpc_server.h"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>

#include <boost/asio/post.hpp>
#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>
#include <grpcpp/server_posix.h>

#include "grpc_front.h"
#include "grpc_reflection.h"
#include "grpc_session.h"
#include "haarcast/net/listener_probe.h"
#include "haarcast/proto/haarcast.grpc.pb.h"

namespace haarcast::net {
namespace {

// How often the health status is brought in line with atCapacity().
constexpr auto kHealthPoll = std::chrono::milliseconds(200);
// How often the port is probed (listener_probe.h), and how long a probe
// waits for the server's SETTINGS: three silent probes in a row, 6 to 9 s,
// mark the port dead. Short enough that SIGTERM waits at most one probe.
constexpr auto kProbeEvery = std::chrono::seconds(2);
constexpr auto kProbeTimeout = std::chrono::milliseconds(1000);
// Past the drain, how long gRPC's Shutdown waits before it cancels the
// streams still open (the drain has already given them drainSeconds).
constexpr auto kShutdownGrace = std::chrono::milliseconds(500);
// The service name the health service reports besides the server's ("").
constexpr const char* kServiceName = "haarcast.v1.Render";

// The Render service with its one method as raw bytes: the session parses
// them itself (RenderSession::onMessage), as it does a WebSocket message.
class RenderGrpcService final : public v1::Render::WithRawCallbackMethod_Session<v1::Render::Service> {
 public:
  RenderGrpcService(Server::Impl& server, GrpcServer& owner) : server_(server), owner_(owner) {}

  grpc::ServerBidiReactor<grpc::ByteBuffer, grpc::ByteBuffer>* Session(grpc::CallbackServerContext* context) override {
    return std::make_shared<GrpcSession>(server_, owner_, context)->start();
  }

 private:
  Server::Impl& server_;
  GrpcServer& owner_;
};

}  // namespace

struct GrpcServer::State {
  State(Server::Impl& s, GrpcServer& owner) : server(s), service(s, owner) {}

  Server::Impl& server;
  RenderGrpcService service;  // outlives grpc (declared first), as reflection does
  // v1alpha comes from libgrpc++'s plugin, which lists what is registered.
  ReflectionV1Service reflection{{kServiceName, "grpc.health.v1.Health", "grpc.reflection.v1.ServerReflection",
                                  "grpc.reflection.v1alpha.ServerReflection"}};
  std::unique_ptr<grpc::Server> grpc;
  // The port itself: accepted by the server's own loop and handed to gRPC
  // (grpc_front.h). Declared after grpc: destroyed first.
  std::unique_ptr<GrpcFront> front;
  int port = 0;

  mutable std::mutex mutex;
  std::map<const GrpcSession*, std::weak_ptr<GrpcSession>> sessions;

  std::mutex healthMutex;
  std::condition_variable healthWake;
  bool healthStop = false;
  std::thread health;
  // Whether the port still accepts: only the health thread writes it.
  ListenerWatch listener;
  std::atomic<bool> listenerDead{false};
  std::string probeHost;  // where the probe connects: the bind address, loopback for a wildcard

  std::atomic<bool> shutdownBegun{false}, shutdownDone{false};
  std::thread stopper;

  void setServing(bool serving) {
    auto* h = grpc->GetHealthCheckService();
    h->SetServingStatus(kServiceName, serving);
    h->SetServingStatus("", serving);
  }

  // Until stopped: SERVING exactly when /readyz would answer 200 and the
  // port accepts; the port probed every kProbeEvery.
  void watchHealth() {
    std::unique_lock lock(healthMutex);
    std::optional<bool> last;
    auto nextProbe = std::chrono::steady_clock::now() + kProbeEvery;
    while (!healthStop) {
      if (std::chrono::steady_clock::now() >= nextProbe) {
        lock.unlock();
        const ProbeResult result = probeHttp2Listener(probeHost, static_cast<std::uint16_t>(port), kProbeTimeout);
        lock.lock();
        nextProbe = std::chrono::steady_clock::now() + kProbeEvery;
        if (listener.record(result)) {
          listenerDead.store(listener.dead());
          if (listener.dead()) {
            server.log("the gRPC port %d stopped answering (no HTTP/2 SETTINGS to 3 probes in a row): /healthz "
                       "answers 503, restart the process", port);
          } else {
            server.log("the gRPC port %d accepts again: /healthz answers 200", port);
          }
        }
      }
      const bool serving = !server.atCapacity() && !listenerDead.load();
      if (serving != last) setServing(serving);
      last = serving;
      healthWake.wait_for(lock, kHealthPoll, [this] { return healthStop; });
    }
  }

  void stopHealth() {
    {
      std::lock_guard lock(healthMutex);
      healthStop = true;
    }
    healthWake.notify_all();
    if (health.joinable()) health.join();
  }
};

GrpcServer::GrpcServer(Server::Impl& server) : state_(std::make_unique<State>(server, *this)) {
  const ServerOptions& o = server.options;
  // Both are process-wide switches read by the builder.
  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  grpc::ServerBuilder builder;
  builder.RegisterService(&state_->service);
  builder.RegisterService(&state_->reflection);
  // As the WebSocket's read limit (upgrade.h): messages up to 4× the
  // protocol's limit reach the session, which answers MESSAGE_TOO_LARGE;
  // larger ones gRPC refuses before buffering (RESOURCE_EXHAUSTED).
  const std::size_t maxReceive = std::min<std::size_t>(4 * o.limits.maxMessageBytes, std::numeric_limits<int>::max());
  builder.SetMaxReceiveMessageSize(static_cast<int>(maxReceive));
  // Client messages are poses of about 100 bytes: nothing to gain from
  // compression, and gRPC 1.51 inflates a compressed message whole before
  // it checks the size (a 63 KB gzip bomb became 64 MB). A compressed
  // message is refused (UNIMPLEMENTED) before it is inflated.
  builder.SetCompressionAlgorithmSupportStatus(GRPC_COMPRESS_DEFLATE, false);
  builder.SetCompressionAlgorithmSupportStatus(GRPC_COMPRESS_GZIP, false);
  // Streams per HTTP/2 connection: what one address may hold anyway
  // (pre-Hello and session slots); the slots are the real limit.
  builder.AddChannelArgument(GRPC_ARG_MAX_CONCURRENT_STREAMS,
                             o.admission.pendingPerAddress + o.admission.sessionsPerAddress);
  // No listening port: the front accepts (grpc_front.h).
  state_->grpc = builder.BuildAndStart();
  if (!state_->grpc) throw std::runtime_error("cannot start the gRPC server");
  state_->front = std::make_unique<GrpcFront>(server, Http2Limits{}, [s = state_.get()](int fd) {
    grpc::AddInsecureChannelFromFd(s->grpc.get(), fd);
  });
  state_->front->start();  // throws naming the address when it cannot listen
  state_->port = state_->front->port();
  // A wildcard bind is probed on loopback, of the same family.
  state_->probeHost = o.bindAddress == "0.0.0.0" ? "127.0.0.1" : o.bindAddress == "::" ? "::1" : o.bindAddress;
  state_->setServing(!server.atCapacity());
  state_->health = std::thread([s = state_.get()] { s->watchHealth(); });
  server.log("gRPC on %s port %d: haarcast.v1.Render, grpc.health.v1.Health, reflection v1 and v1alpha",
             o.bindAddress.c_str(), state_->port);
}

GrpcServer::~GrpcServer() { join(); }

std::uint16_t GrpcServer::port() const { return static_cast<std::uint16_t>(state_->port); }

std::optional<std::string> GrpcServer::listenerProblem() const {
  if (!state_->listenerDead.load()) return std::nullopt;
  return "the gRPC port " + std::to_string(state_->port) + " stopped answering HTTP/2: restart the process";
}

std::string GrpcServer::peerGroup(std::string_view peer) const {
  return state_->front ? state_->front->peerGroup(peer) : std::string(peer);
}

std::size_t GrpcServer::sessionCount() const {
  std::lock_guard lock(state_->mutex);
  return state_->sessions.size();
}

void GrpcServer::add(const GrpcSession* session, std::weak_ptr<GrpcSession> weak) {
  std::lock_guard lock(state_->mutex);
  state_->sessions.emplace(session, std::move(weak));
}

void GrpcServer::remove(const GrpcSession* session) {
  std::lock_guard lock(state_->mutex);
  state_->sessions.erase(session);
}

void GrpcServer::stopSessions() {
  state_->setServing(false);  // at once; the health thread agrees (atCapacity() is true while stopping)
  std::vector<std::shared_ptr<GrpcSession>> open;
  {
    std::lock_guard lock(state_->mutex);
    for (auto& [ptr, weak] : state_->sessions) {
      if (auto s = weak.lock()) open.push_back(std::move(s));
    }
  }
  // Outside the lock: a session's destructor takes it.
  for (auto& s : open) boost::asio::post(s->executor(), [s] { s->shutdown(); });
}

void GrpcServer::shutdownThen(std::function<void()> then) {
  if (state_->shutdownBegun.exchange(true)) {
    if (then) then();
    return;
  }
  state_->stopHealth();
  if (state_->front) state_->front->close();
  state_->stopper = std::thread([s = state_.get(), then = std::move(then)] {
    s->grpc->Shutdown(std::chrono::system_clock::now() + kShutdownGrace);
    s->shutdownDone.store(true);
    if (then) then();
  });
}

void GrpcServer::join() {
  if (!state_->shutdownBegun.load()) {
    shutdownThen(nullptr);
    // No I/O thread runs (the Server was never started, or is being
    // destroyed): the streams finish on their strands, so run them here.
    auto& ioc = state_->server.ioc;
    while (!state_->shutdownDone.load()) {
      ioc.restart();
      ioc.run_for(std::chrono::milliseconds(20));
    }
  }
  if (state_->stopper.joinable()) state_->stopper.join();
  // The front's acceptor belongs to the Server's io_context, which is
  // destroyed before this object (server_impl.h): it goes now, while the
  // io_context is alive. gRPC is shut down: no stream asks for a peer.
  state_->front.reset();
}

}  // namespace haarcast::net
