#include "haarcast/net/server.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdarg>
#include <cstdio>
#include <deque>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include "haarcast/net/static_files.h"

namespace haarcast::net {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using Clock = std::chrono::steady_clock;

// How often a session checks its timeouts and whether Stats are due.
constexpr auto kTick = std::chrono::milliseconds(100);
// Control messages (Welcome, Error, Stats, Pong) queued behind the write in
// flight; a client that lets this many pile up is not reading.
constexpr std::size_t kMaxControlQueue = 64;
// HTTP requests are small: a GET and its headers.
constexpr std::uint32_t kMaxHttpHeaderBytes = 16 * 1024;
constexpr std::uint64_t kMaxHttpBodyBytes = 16 * 1024;
constexpr std::uintmax_t kMaxStaticFileBytes = 32u << 20;

std::chrono::nanoseconds toDuration(double seconds) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(std::max(0.0, seconds)));
}

double secondsBetween(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

// "ERROR_CODE_BAD_MESSAGE" → "bad_message": the /metrics label.
std::string errorLabel(v1::ErrorCode code) {
  std::string name = v1::ErrorCode_Name(code);
  constexpr std::string_view prefix = "ERROR_CODE_";
  if (name.rfind(prefix, 0) == 0) name = name.substr(prefix.size());
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return name;
}

// Equal-time comparison: the token check does not leak how much matched.
bool tokensEqual(std::string_view given, std::string_view expected) {
  if (given.size() != expected.size() || expected.empty()) return false;
  unsigned diff = 0;
  for (std::size_t i = 0; i < given.size(); ++i) {
    diff |= static_cast<unsigned>(static_cast<unsigned char>(given[i]) ^ static_cast<unsigned char>(expected[i]));
  }
  return diff == 0;
}

std::string toString(beast::string_view s) { return std::string(s.data(), s.size()); }

class WsSession;

}  // namespace

struct Server::Impl {
  ServerOptions options;
  Catalog catalog;
  Metrics metrics;
  std::mutex logMutex;
  std::mutex sessionsMutex;
  std::map<const WsSession*, std::weak_ptr<WsSession>> sessions;
  std::atomic<bool> stopping{false};
  std::atomic<std::uint64_t> nextSessionId{1};
  std::vector<std::thread> threads;

  // Declared after everything sessions touch in their destructors, so that
  // the handlers the io_context destroys find them alive; the render service
  // after the io_context, so its threads (which post into it) stop first.
  asio::io_context ioc;
  tcp::acceptor acceptor;
  std::optional<asio::signal_set> signals;
  asio::steady_timer drainTimer;
  Clock::time_point drainDeadline;
  std::unique_ptr<RenderService> renderService;

  Impl(ServerOptions o, Catalog c, RendererBuilder builder)
      : options(std::move(o)),
        catalog(std::move(c)),
        ioc(std::max(1, options.ioThreads)),
        acceptor(asio::make_strand(ioc)),
        drainTimer(ioc),
        renderService(std::make_unique<RenderService>(std::move(builder), options.render, metrics)) {}

  void log(const char* format, ...) __attribute__((format(printf, 2, 3))) {
    if (!options.log) return;
    std::lock_guard lock(logMutex);
    std::va_list args;
    va_start(args, format);
    std::fputs("[serve] ", stderr);
    std::vfprintf(stderr, format, args);
    std::fputc('\n', stderr);
    va_end(args);
  }

  void listen() {
    beast::error_code ec;
    const auto address = asio::ip::make_address(options.bindAddress, ec);
    if (ec) throw std::runtime_error("--bind " + options.bindAddress + " is not an IP address: " + ec.message());
    const tcp::endpoint endpoint(address, options.port);
    const std::string where = options.bindAddress + ":" + std::to_string(options.port);
    acceptor.open(endpoint.protocol(), ec);
    if (!ec) acceptor.set_option(asio::socket_base::reuse_address(true), ec);
    if (!ec) acceptor.bind(endpoint, ec);
    if (!ec) acceptor.listen(asio::socket_base::max_listen_connections, ec);
    if (ec) throw std::runtime_error("cannot listen on " + where + ": " + ec.message());
    boundPort = acceptor.local_endpoint(ec).port();
  }
  std::uint16_t boundPort = 0;

  void doAccept();
  void stop();
  void watchDrain();
  std::size_t sessionCount() {
    std::lock_guard lock(sessionsMutex);
    return sessions.size();
  }
  void countError(v1::ErrorCode code) { metrics.addError(errorLabel(code)); }
};

namespace {

using Impl = Server::Impl;

// ------------------------------------------------------------------ WebSocket

class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(Impl& server, tcp::socket&& socket)
      : server_(server),
        ws_(std::move(socket)),
        executor_(ws_.get_executor()),
        ticker_(executor_),
        paceTimer_(executor_),
        id_("s" + std::to_string(server.nextSessionId.fetch_add(1))) {
    beast::error_code ec;
    const auto remote = beast::get_lowest_layer(ws_).socket().remote_endpoint(ec);
    peer_ = ec ? std::string("?") : remote.address().to_string() + ":" + std::to_string(remote.port());
  }

  ~WsSession() {
    if (registered_) {
      server_.metrics.sessions.fetch_sub(1);
      std::lock_guard lock(server_.sessionsMutex);
      server_.sessions.erase(this);
    }
  }

  template <class Body, class Allocator>
  void accept(http::request<Body, http::basic_fields<Allocator>> request) {
    const auto& limits = server_.options.limits;
    // The WebSocket stream keeps its own timeouts; the TCP layer's must be off.
    beast::get_lowest_layer(ws_).expires_never();
    websocket::stream_base::timeout timeouts{};
    timeouts.handshake_timeout = toDuration(server_.options.handshakeSeconds);
    timeouts.idle_timeout = websocket::stream_base::none();  // ours: Error TIMEOUT, with a reason
    timeouts.keep_alive_pings = false;
    ws_.set_option(timeouts);
    ws_.set_option(websocket::stream_base::decorator(
        [](websocket::response_type& res) { res.set(http::field::server, kServerVersion); }));
    // A backstop only: messages over maxMessageBytes get Error
    // MESSAGE_TOO_LARGE in onRead; far larger ones are cut by Beast here
    // (close code 1009) before they are buffered.
    ws_.read_message_max(limits.maxMessageBytes * 4 + 4096);
    ws_.binary(true);
    clientName_ = toString(request[http::field::user_agent]);
    ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) { self->onAccept(ec); });
  }

  // From Server::stop(), posted to the strand.
  void shutdown() { fail({v1::ERROR_CODE_SHUTTING_DOWN, "the server is shutting down", true}, websocket::close_code::going_away); }

  const asio::any_io_executor& executor() const { return executor_; }

 private:
  struct Outgoing {
    std::shared_ptr<const std::string> bytes;
    bool isFrame = false;
    std::size_t payloadBytes = 0;
  };

  // What a render job reads on the worker and the strand reads back.
  struct JobContext {
    std::uint64_t poseSequence = 0;
    double clientTimeMs = 0.0;
    Clock::time_point poseReceived;
    SessionConfig config;
  };

  void onAccept(beast::error_code ec) {
    if (ec) {
      server_.log("%s: WebSocket handshake with %s failed: %s", id_.c_str(), peer_.c_str(), ec.message().c_str());
      return;
    }
    opened_ = lastMessage_ = lastStats_ = Clock::now();
    bool full = false;
    {
      std::lock_guard lock(server_.sessionsMutex);
      full = server_.sessions.size() >= static_cast<std::size_t>(std::max(0, server_.options.limits.maxSessions));
      if (!full) {
        server_.sessions.emplace(this, weak_from_this());
        registered_ = true;
      }
    }
    if (registered_) {
      server_.metrics.sessions.fetch_add(1);
      server_.metrics.sessionsTotal.fetch_add(1);
    }
    server_.log("%s: opened from %s", id_.c_str(), peer_.c_str());
    doRead();
    tick();
    if (full) {
      fail({v1::ERROR_CODE_TOO_MANY_SESSIONS,
            "too many sessions: the server allows " + std::to_string(server_.options.limits.maxSessions), true},
           websocket::close_code::try_again_later);
    } else if (server_.stopping.load()) {
      shutdown();
    }
  }

  // ---- reading

  void doRead() {
    ws_.async_read(readBuffer_, [self = shared_from_this()](beast::error_code ec, std::size_t) { self->onRead(ec); });
  }

  void onRead(beast::error_code ec) {
    if (ec) {
      if (ec == websocket::error::message_too_big) {
        server_.countError(v1::ERROR_CODE_MESSAGE_TOO_LARGE);
        server_.log("%s: message over %zu bytes: closed (1009)", id_.c_str(), ws_.read_message_max());
      } else if (ec != websocket::error::closed && ec != asio::error::operation_aborted) {
        server_.log("%s: read: %s", id_.c_str(), ec.message().c_str());
      }
      finish();
      return;
    }
    const std::string bytes = beast::buffers_to_string(readBuffer_.data());
    readBuffer_.consume(readBuffer_.size());
    if (!closeRequested_) handleMessage(bytes, ws_.got_binary());
    doRead();  // also while closing: the close handshake needs the peer's close frame read
  }

  void handleMessage(const std::string& bytes, bool binary) {
    lastMessage_ = Clock::now();
    const auto& limits = server_.options.limits;
    if (bytes.size() > limits.maxMessageBytes) {
      fail({v1::ERROR_CODE_MESSAGE_TOO_LARGE,
            "message of " + std::to_string(bytes.size()) + " bytes is over the limit of " +
                std::to_string(limits.maxMessageBytes),
            true},
           websocket::close_code::too_big);
      return;
    }
    auto parsed = parseClientMessage(bytes);
    if (auto* e = std::get_if<ProtocolError>(&parsed)) {
      if (!binary) e->message = "text message: " + e->message + " (send protobuf as binary messages)";
      badMessage(std::move(*e));
      return;
    }
    const auto& message = std::get<v1::ClientMessage>(parsed);
    if (!hello_ && message.body_case() != v1::ClientMessage::kHello) {
      fail({v1::ERROR_CODE_PROTOCOL_ORDER, "the first message must be a Hello", true});
      return;
    }
    switch (message.body_case()) {
      case v1::ClientMessage::kHello: onHello(message.hello()); break;
      case v1::ClientMessage::kPose: onPose(message.pose()); break;
      case v1::ClientMessage::kSettings: onSettings(message.settings()); break;
      case v1::ClientMessage::kScene: onScene(message.scene()); break;
      case v1::ClientMessage::kPing: {
        v1::ServerMessage pong;
        pong.mutable_pong()->set_nonce(message.ping().nonce());
        send(serialize(pong));
        break;
      }
      case v1::ClientMessage::BODY_NOT_SET: break;  // parseClientMessage rejects it
    }
  }

  void badMessage(ProtocolError e) {
    ++badMessages_;
    if (badMessages_ > server_.options.limits.maxBadMessages) {
      e.message += "; too many bad messages (" + std::to_string(badMessages_) + ")";
      e.fatal = true;
      fail(std::move(e));
    } else {
      sendError(e);
    }
  }

  void onHello(const v1::Hello& hello) {
    if (hello_) {
      sendError({v1::ERROR_CODE_PROTOCOL_ORDER, "a second Hello: send RenderSettings or SceneChoice to change settings", false});
      return;
    }
    const auto& token = server_.options.token;
    if (!token.empty() && !hello.auth_token().empty() && !tokensEqual(hello.auth_token(), token)) {
      fail({v1::ERROR_CODE_UNAUTHORIZED, "wrong auth_token in Hello", true});
      return;
    }
    auto config = configFromHello(hello, server_.options.limits, server_.options.defaults, server_.catalog);
    if (auto* e = std::get_if<ProtocolError>(&config)) {
      fail(std::move(*e));
      return;
    }
    hello_ = true;
    if (!hello.client_name().empty()) clientName_ = hello.client_name().substr(0, 64);
    const auto* scene = server_.catalog.findScene(std::get<SessionConfig>(config).scene);
    {
      std::lock_guard lock(mutex_);
      config_ = std::get<SessionConfig>(std::move(config));
      pose_ = initialPose(scene->camera, scene->poses);
      poseReceived_ = Clock::now();
    }
    server_.log("%s: hello from \"%s\": %dx%d %s, %.1f fps, level %d, %s, scene %s", id_.c_str(), clientName_.c_str(),
                config_.width, config_.height, std::string(encodingName(config_.encoding)).c_str(), config_.fps,
                config_.level, std::string(methodName(config_.method)).c_str(), config_.scene.c_str());
    prepareRenderer();
  }

  void onPose(const v1::PoseUpdate& update) {
    std::optional<ProtocolError> e;
    bool applied = false;
    {
      std::lock_guard lock(mutex_);
      const auto before = pose_.sequence;
      e = applyPose(pose_, update);
      applied = pose_.sequence != before;
      if (applied) poseReceived_ = Clock::now();
    }
    if (e) {
      badMessage(std::move(*e));
      return;
    }
    if (applied) {
      wantFrame_ = true;
      maybeRender();
    }
  }

  void onSettings(const v1::RenderSettings& settings) {
    SessionConfig next = config_;
    if (auto e = applySettings(next, settings, server_.options.limits, server_.catalog)) {
      sendError(*e);
      return;
    }
    adopt(std::move(next), false, false);
  }

  void onScene(const v1::SceneChoice& choice) {
    SessionConfig next = config_;
    if (auto e = applySceneChoice(next, choice, server_.catalog)) {
      sendError(*e);
      return;
    }
    const bool newScene = next.scene != config_.scene;
    adopt(std::move(next), newScene, true);
  }

  // A changed config: a new renderer when its key changed; the scene's own
  // view again when the scene did (the objects are others). An accepted
  // SceneChoice is answered with the scene's SceneInfo.
  void adopt(SessionConfig next, bool newScene, bool announceScene) {
    const bool newRenderer = next.rendererKey() != config_.rendererKey();
    {
      std::lock_guard lock(mutex_);
      // Auto exposure starts afresh for another scene or after a fixed spell.
      if (newScene || !next.autoExposure) lastExposure_.reset();
      config_ = std::move(next);
      if (newScene) {
        const auto* scene = server_.catalog.findScene(config_.scene);
        const auto sequence = pose_.sequence;
        pose_ = initialPose(scene->camera, scene->poses);
        pose_.sequence = sequence;  // later poses stay newer
      }
    }
    if (announceScene && welcomed_) {
      v1::ServerMessage m;
      *m.mutable_scene_info() = sceneInfo(config_, server_.catalog);
      send(serialize(m));
    }
    wantFrame_ = true;
    if (newRenderer) {
      prepareRenderer();
    } else {
      maybeRender();
    }
  }

  void prepareRenderer() {
    renderer_.reset();  // no frames until the renderer for the new config is ready
    const std::string key = config_.rendererKey();
    server_.renderService->prepare(config_, [weak = weak_from_this(), key](std::shared_ptr<PreparedRenderer> r,
                                                                           std::string error) {
      if (auto self = weak.lock()) {
        asio::post(self->executor_, [self, key, r = std::move(r), error = std::move(error)]() mutable {
          self->onPrepared(key, std::move(r), error);
        });
      }
    });
  }

  void onPrepared(const std::string& key, std::shared_ptr<PreparedRenderer> r, const std::string& error) {
    if (gone_ || closeRequested_ || key != config_.rendererKey()) return;  // superseded
    if (!r) {
      fail({v1::ERROR_CODE_RENDER_FAILED, "cannot prepare the renderer: " + error, !welcomed_});
      return;
    }
    renderer_ = std::move(r);
    if (!welcomed_) {
      welcomed_ = true;
      v1::ServerMessage m;
      auto* w = m.mutable_welcome();
      w->set_protocol_version(kProtocolVersion);
      w->set_session_id(id_);
      w->set_server_version(kServerVersion);
      w->set_width(static_cast<std::uint32_t>(config_.width));
      w->set_height(static_cast<std::uint32_t>(config_.height));
      w->set_encoding(toWire(config_.encoding));
      w->set_fps_cap(config_.fps);
      for (const auto& s : server_.catalog.scenes) w->add_scenes(s.name);
      for (const auto& mat : server_.catalog.materials) w->add_materials(mat);
      *w->mutable_settings() = settingsToWire(config_);
      w->set_object_count(static_cast<std::uint32_t>(renderer_->renderer->objectCount()));
      w->set_device(renderer_->renderer->deviceName());
      *w->mutable_scene_info() = sceneInfo(config_, server_.catalog);
      *w->mutable_limits() = limitsToWire(server_.options.limits);
      send(serialize(m));
    }
    wantFrame_ = true;
    maybeRender();
  }

  // ---- rendering, paced to the session's fps cap

  void maybeRender() {
    if (!renderer_ || inFlight_ || !wantFrame_ || closeRequested_ || gone_) return;
    const auto now = Clock::now();
    if (now < nextFrameAt_) {
      if (!paceArmed_) {
        paceArmed_ = true;
        paceTimer_.expires_at(nextFrameAt_);
        paceTimer_.async_wait([self = shared_from_this()](beast::error_code ec) {
          self->paceArmed_ = false;
          if (!ec) self->maybeRender();
        });
      }
      return;
    }
    wantFrame_ = false;
    inFlight_ = true;
    nextFrameAt_ = now + toDuration(1.0 / std::max(config_.fps, 1e-3));
    auto context = std::make_shared<JobContext>();
    RenderJob job;
    job.renderer = renderer_;
    job.encoding = config_.encoding;
    job.jpegQuality = config_.jpegQuality;
    job.take = [weak = weak_from_this(), context]() -> std::optional<render::FrameRequest> {
      const auto self = weak.lock();
      if (!self) return std::nullopt;
      std::lock_guard lock(self->mutex_);
      if (self->closing_.load()) return std::nullopt;
      context->poseSequence = self->pose_.sequence;
      context->clientTimeMs = self->pose_.clientTimeMs;
      context->poseReceived = self->poseReceived_;
      context->config = self->config_;
      render::FrameRequest request = frameRequest(self->pose_, self->config_);
      if (request.exposure.automatic && self->lastExposure_) {
        request.exposure.previousStops = self->lastExposure_;
        request.exposure.adaptation = render::exposureAdaptation(secondsBetween(self->lastExposureAt_, Clock::now()));
      }
      return request;
    };
    job.done = [weak = weak_from_this(), context](std::optional<RenderedFrame> frame, std::string error) {
      if (auto self = weak.lock()) {
        asio::post(self->executor_, [self, context, frame = std::move(frame), error = std::move(error)]() mutable {
          self->onRendered(*context, std::move(frame), error);
        });
      }
    };
    server_.renderService->submit(std::move(job));
  }

  void onRendered(const JobContext& context, std::optional<RenderedFrame> rendered, const std::string& error) {
    inFlight_ = false;
    if (gone_ || closeRequested_) return;
    if (!rendered) {
      // Once per distinct message: a broken config must not flood the client.
      if (error != lastRenderError_) sendError({v1::ERROR_CODE_RENDER_FAILED, error, false});
      lastRenderError_ = error;
      return;
    }
    lastRenderError_.clear();
    if (context.config.autoExposure) {
      std::lock_guard lock(mutex_);
      if (config_.autoExposure && config_.scene == context.config.scene) {
        lastExposure_ = rendered->frame.exposureStops;
        lastExposureAt_ = Clock::now();
      }
    }
    auto stages = rendered->frame.stages;
    stages.push_back({"encode", rendered->encodeSeconds});
    server_.metrics.addStages(stages);
    periodRenderSeconds_ += rendered->frame.seconds;
    ++periodRendered_;

    v1::ServerMessage m;
    auto* f = m.mutable_frame();
    f->set_sequence(++frameSequence_);
    f->set_pose_sequence(context.poseSequence);
    f->set_width(static_cast<std::uint32_t>(rendered->frame.width));
    f->set_height(static_cast<std::uint32_t>(rendered->frame.height));
    f->set_encoding(toWire(context.config.encoding));
    const std::size_t payload = rendered->encoded.size();
    f->set_data(std::move(rendered->encoded));
    for (const auto& s : stages) {
      auto* t = f->add_timings();
      t->set_name(s.name);
      t->set_ms(s.seconds * 1e3);
    }
    f->set_client_time_ms(context.clientTimeMs);
    f->set_server_ms(secondsBetween(context.poseReceived, Clock::now()) * 1e3);
    *f->mutable_settings() = settingsToWire(context.config);
    f->set_exposure_stops(rendered->frame.exposureStops);

    if (frameSlot_) {  // the client has not taken the last one yet: latest wins
      ++framesDropped_;
      server_.metrics.framesDropped.fetch_add(1);
    }
    frameSlot_ = Outgoing{std::make_shared<const std::string>(serialize(m)), true, payload};
    doWrite();
    maybeRender();
  }

  // ---- writing: one in flight, control messages first, then the frame slot

  void send(std::string bytes) {
    if (closeRequested_ || gone_) return;
    if (control_.size() >= kMaxControlQueue) {
      hardClose("outgoing queue full (the client is not reading)");
      return;
    }
    control_.push_back(Outgoing{std::make_shared<const std::string>(std::move(bytes)), false, 0});
    doWrite();
  }

  void sendError(const ProtocolError& e) {
    server_.countError(e.code);
    if (e.fatal) {
      fail(e);
      return;
    }
    server_.log("%s: error %s: %s", id_.c_str(), errorLabel(e.code).c_str(), e.message.c_str());
    send(errorMessage(e));
  }

  // A fatal error: send it, let the writes queued before it go, then close.
  void fail(ProtocolError e, websocket::close_code code = websocket::close_code::policy_error) {
    if (closeRequested_ || gone_) return;
    e.fatal = true;
    server_.countError(e.code);
    server_.log("%s: closing, %s: %s", id_.c_str(), errorLabel(e.code).c_str(), e.message.c_str());
    control_.push_back(Outgoing{std::make_shared<const std::string>(errorMessage(e)), false, 0});
    closeRequested_ = true;
    closing_.store(true);
    closeAt_ = Clock::now();
    // The close reason is limited to 123 bytes by RFC 6455.
    closeReason_ = websocket::close_reason(code, e.message.substr(0, 120));
    frameSlot_.reset();
    paceTimer_.cancel();
    doWrite();
  }

  void doWrite() {
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

  void onWrite(beast::error_code ec, const Outgoing& sent) {
    writing_ = false;
    if (ec) {
      if (ec != asio::error::operation_aborted) server_.log("%s: write: %s", id_.c_str(), ec.message().c_str());
      finish();
      return;
    }
    if (sent.isFrame) {
      ++framesSent_;
      ++periodFrames_;
      bytesSent_ += sent.payloadBytes;
      server_.metrics.framesTotal.fetch_add(1);
      server_.metrics.bytesTotal.fetch_add(sent.payloadBytes);
    }
    doWrite();
  }

  void startClose() {
    closeStarted_ = true;
    ws_.async_close(closeReason_, [self = shared_from_this()](beast::error_code) { self->finish(); });
  }

  // Cuts the connection: pending operations complete with operation_aborted.
  void hardClose(const char* why) {
    if (gone_) return;
    server_.log("%s: cut: %s", id_.c_str(), why);
    closing_.store(true);
    closeRequested_ = true;
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().shutdown(tcp::socket::shutdown_both, ec);
    beast::get_lowest_layer(ws_).socket().close(ec);
    finish();
  }

  // The session is over: stop the timers; it is destroyed when the last
  // pending handler lets go of it.
  void finish() {
    if (gone_) return;
    gone_ = true;
    closing_.store(true);
    ticker_.cancel();
    paceTimer_.cancel();
    server_.log("%s: closed (%llu frames, %llu dropped, %llu bytes)", id_.c_str(),
                static_cast<unsigned long long>(framesSent_), static_cast<unsigned long long>(framesDropped_),
                static_cast<unsigned long long>(bytesSent_));
  }

  // ---- timeouts and Stats

  void tick() {
    ticker_.expires_after(kTick);
    ticker_.async_wait([self = shared_from_this()](beast::error_code ec) {
      if (!ec) self->onTick();
    });
  }

  void onTick() {
    if (gone_) return;
    const auto& o = server_.options;
    const auto now = Clock::now();
    if (writing_ && secondsBetween(writeStarted_, now) > o.writeStallSeconds) {
      server_.countError(v1::ERROR_CODE_TIMEOUT);
      hardClose("a write has not completed for too long (the client stopped reading)");
      return;
    }
    if (closeRequested_ && secondsBetween(closeAt_, now) > o.drainSeconds) {
      hardClose("the close did not complete in time");
      return;
    }
    if (!closeRequested_) {
      if (!hello_ && secondsBetween(opened_, now) > o.handshakeSeconds) {
        fail({v1::ERROR_CODE_TIMEOUT, "no Hello within " + std::to_string(o.handshakeSeconds) + " s", true});
      } else if (secondsBetween(lastMessage_, now) > o.idleSeconds) {
        fail({v1::ERROR_CODE_TIMEOUT, "no message for " + std::to_string(o.idleSeconds) + " s (idle)", true});
      } else if (welcomed_ && secondsBetween(lastStats_, now) >= o.statsSeconds) {
        sendStats(now);
      }
    }
    tick();
  }

  void sendStats(Clock::time_point now) {
    const double period = secondsBetween(lastStats_, now);
    lastStats_ = now;
    v1::ServerMessage m;
    auto* s = m.mutable_stats();
    s->set_frames_sent(framesSent_);
    s->set_frames_dropped(framesDropped_);
    s->set_bytes_sent(bytesSent_);
    s->set_fps(period > 0 ? static_cast<double>(periodFrames_) / period : 0.0);
    s->set_render_ms_mean(periodRendered_ ? periodRenderSeconds_ * 1e3 / static_cast<double>(periodRendered_) : 0.0);
    s->set_sessions(static_cast<std::uint32_t>(std::max<std::int64_t>(0, server_.metrics.sessions.load())));
    periodFrames_ = periodRendered_ = 0;
    periodRenderSeconds_ = 0.0;
    // Stats are the one message that may be skipped: never queue them behind a backlog.
    if (control_.size() < 4) send(serialize(m));
  }

  Impl& server_;
  websocket::stream<beast::tcp_stream> ws_;
  asio::any_io_executor executor_;  // the strand the socket was accepted on
  asio::steady_timer ticker_, paceTimer_;
  beast::flat_buffer readBuffer_;
  std::string id_, peer_, clientName_;
  bool registered_ = false;

  // Strand state.
  bool hello_ = false, welcomed_ = false, wantFrame_ = false, inFlight_ = false, paceArmed_ = false;
  bool writing_ = false, closeRequested_ = false, closeStarted_ = false, gone_ = false;
  int badMessages_ = 0;
  std::shared_ptr<PreparedRenderer> renderer_;
  std::deque<Outgoing> control_;
  std::optional<Outgoing> frameSlot_;
  websocket::close_reason closeReason_;
  Clock::time_point opened_, lastMessage_, lastStats_, writeStarted_, closeAt_, nextFrameAt_{};
  std::uint64_t frameSequence_ = 0, framesSent_ = 0, framesDropped_ = 0, bytesSent_ = 0;
  std::uint64_t periodFrames_ = 0, periodRendered_ = 0;
  double periodRenderSeconds_ = 0.0;
  std::string lastRenderError_;

  // Shared with the render worker (take()): under mutex_. config_ is written
  // on the strand under the lock and read there without it.
  std::mutex mutex_;
  SessionConfig config_;
  PoseState pose_;
  Clock::time_point poseReceived_;
  // Auto exposure: the last frame's exposure, eased from (tonemap.h).
  std::optional<double> lastExposure_;
  Clock::time_point lastExposureAt_;
  std::atomic<bool> closing_{false};
};

// ------------------------------------------------------------------ HTTP

class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(Impl& server, tcp::socket&& socket) : server_(server), stream_(std::move(socket)) {}

  void run() {
    asio::dispatch(stream_.get_executor(), [self = shared_from_this()] { self->doRead(); });
  }

 private:
  using Response = http::response<http::string_body>;

  void doRead() {
    parser_.emplace();
    parser_->header_limit(kMaxHttpHeaderBytes);
    parser_->body_limit(kMaxHttpBodyBytes);
    stream_.expires_after(toDuration(server_.options.handshakeSeconds));
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) { self->onRead(ec); });
  }

  void onRead(beast::error_code ec) {
    if (ec == http::error::end_of_stream) {
      stream_.socket().shutdown(tcp::socket::shutdown_send, ec);
      return;
    }
    if (ec) {
      // A request we cannot parse gets a 400 naming why; timeouts and
      // resets just end the connection.
      if (ec.category() == http::make_error_code(http::error::bad_target).category()) {
        http::request<http::string_body> dummy;
        respond(dummy, http::status::bad_request, "bad request: " + ec.message() + "\n", "text/plain", false);
      }
      return;
    }
    auto request = parser_->release();
    if (websocket::is_upgrade(request)) {
      upgrade(std::move(request));
      return;
    }
    serve(request);
  }

  void upgrade(http::request<http::string_body> request) {
    const std::string_view target(request.target().data(), request.target().size());
    if (targetPath(target) != "/ws") {
      respond(request, http::status::not_found, "no WebSocket at " + std::string(targetPath(target)) + " (use /ws)\n",
              "text/plain", false);
      return;
    }
    if (const auto& token = server_.options.token; !token.empty()) {
      std::string given = queryParameter(target, "token");
      const std::string_view auth(request[http::field::authorization].data(), request[http::field::authorization].size());
      if (given.empty() && auth.rfind("Bearer ", 0) == 0) given = std::string(auth.substr(7));
      if (!tokensEqual(given, token)) {
        server_.countError(v1::ERROR_CODE_UNAUTHORIZED);
        server_.log("upgrade from %s refused: %s token", remote().c_str(), given.empty() ? "no" : "wrong");
        Response res{http::status::unauthorized, request.version()};
        res.set(http::field::www_authenticate, "Bearer");
        respond(request, std::move(res),
                given.empty() ? "unauthorized: no token (use ?token=T or Authorization: Bearer T)\n"
                              : "unauthorized: wrong token\n",
                "text/plain", false);
        return;
      }
    }
    if (server_.stopping.load()) {
      respond(request, http::status::service_unavailable, "the server is shutting down\n", "text/plain", false);
      return;
    }
    std::make_shared<WsSession>(server_, stream_.release_socket())->accept(std::move(request));
  }

  void serve(const http::request<http::string_body>& request) {
    server_.metrics.httpRequests.fetch_add(1);
    const std::string_view target(request.target().data(), request.target().size());
    const std::string_view path = targetPath(target);
    const bool keepAlive = request.keep_alive() && !server_.stopping.load();
    if (request.method() != http::verb::get && request.method() != http::verb::head) {
      Response res{http::status::method_not_allowed, request.version()};
      res.set(http::field::allow, "GET, HEAD");
      respond(request, std::move(res), "method not allowed: use GET\n", "text/plain", keepAlive);
      return;
    }
    if (path == "/healthz") {
      respond(request, http::status::ok, "ok\n", "text/plain", keepAlive);
      return;
    }
    if (path == "/metrics") {
      respond(request, http::status::ok, server_.metrics.prometheusText(), "text/plain; version=0.0.4; charset=utf-8",
              keepAlive);
      return;
    }
    std::optional<std::filesystem::path> file;
    if (path == "/haarcast.proto") {
      if (!server_.options.protoFile.empty()) file = server_.options.protoFile;
    } else if (!server_.options.webRoot.empty()) {
      file = resolveStaticFile(server_.options.webRoot, path);
    }
    std::string body;
    if (file && readFile(*file, body)) {
      respond(request, http::status::ok, std::move(body), std::string(contentType(*file)), keepAlive);
      return;
    }
    respond(request, http::status::not_found, "not found: " + std::string(path) + "\n", "text/plain", keepAlive);
  }

  static bool readFile(const std::filesystem::path& file, std::string& body) {
    std::error_code ec;
    const auto size = std::filesystem::file_size(file, ec);
    if (ec || size > kMaxStaticFileBytes) return false;
    std::ifstream in(file, std::ios::binary);
    if (!in) return false;
    std::ostringstream s;
    s << in.rdbuf();
    body = std::move(s).str();
    return true;
  }

  template <class Request>
  void respond(const Request& request, http::status status, std::string body, const std::string& type, bool keepAlive) {
    respond(request, Response{status, request.version() ? request.version() : 11}, std::move(body), type, keepAlive);
  }

  template <class Request>
  void respond(const Request& request, Response res, std::string body, const std::string& type, bool keepAlive) {
    res.set(http::field::server, kServerVersion);
    res.set(http::field::content_type, type);
    res.set(http::field::cache_control, "no-cache");
    res.keep_alive(keepAlive);
    const bool head = request.method() == http::verb::head;
    res.body() = std::move(body);
    res.prepare_payload();  // Content-Length of the body, also for HEAD
    if (head) res.body().clear();
    auto shared = std::make_shared<Response>(std::move(res));
    http::async_write(stream_, *shared, [self = shared_from_this(), shared, keepAlive](beast::error_code ec, std::size_t) {
      if (ec) return;
      if (!keepAlive) {
        self->stream_.socket().shutdown(tcp::socket::shutdown_send, ec);
        return;
      }
      self->doRead();
    });
  }

  std::string remote() {
    beast::error_code ec;
    const auto e = stream_.socket().remote_endpoint(ec);
    return ec ? std::string("?") : e.address().to_string() + ":" + std::to_string(e.port());
  }

  Impl& server_;
  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
};

}  // namespace

// ------------------------------------------------------------------ Server

void Server::Impl::doAccept() {
  acceptor.async_accept(asio::make_strand(ioc), [this](beast::error_code ec, tcp::socket socket) {
    if (!acceptor.is_open()) return;
    if (ec) {
      log("accept: %s", ec.message().c_str());
    } else {
      // Frames are small writes answered by small pose messages: without
      // this, Nagle's algorithm holds a frame's last segment until the
      // client's delayed ACK (40 ms on Linux), a stall on every frame.
      beast::error_code ignored;
      socket.set_option(tcp::no_delay(true), ignored);
      std::make_shared<HttpSession>(*this, std::move(socket))->run();
    }
    doAccept();
  });
}

void Server::Impl::stop() {
  if (stopping.exchange(true)) return;
  log("stopping: draining %zu sessions", sessionCount());
  asio::post(acceptor.get_executor(), [this] {
    beast::error_code ec;
    acceptor.close(ec);
  });
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
  asio::post(ioc, [this] {
    if (signals) signals->cancel();
    drainDeadline = Clock::now() + toDuration(options.drainSeconds + 0.5);
    watchDrain();
  });
}

// Stops the io_context once every session has closed (HTTP keep-alive
// connections are not waited for), or at the drain deadline.
void Server::Impl::watchDrain() {
  if (sessionCount() == 0 || Clock::now() >= drainDeadline) {
    log("stopped (%zu sessions cut)", sessionCount());
    ioc.stop();
    return;
  }
  drainTimer.expires_after(std::chrono::milliseconds(20));
  drainTimer.async_wait([this](beast::error_code ec) {
    if (!ec) watchDrain();
  });
}

Server::Server(ServerOptions options, Catalog catalog, RendererBuilder builder)
    : impl_(std::make_shared<Impl>(std::move(options), std::move(catalog), std::move(builder))) {
  if (impl_->catalog.scenes.empty()) throw std::invalid_argument("the server needs at least one scene");
  if (impl_->options.handleSignals) {
    impl_->signals.emplace(impl_->ioc, SIGINT, SIGTERM);
    impl_->signals->async_wait([impl = impl_.get()](beast::error_code ec, int signal) {
      if (ec) return;
      impl->log("signal %d", signal);
      impl->stop();
    });
  }
  impl_->listen();
  impl_->doAccept();
}

Server::~Server() {
  stop();
  wait();
  impl_->renderService->stop();
}

std::uint16_t Server::port() const {
  return impl_->boundPort;
}

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
  impl_->renderService->stop();
}

void Server::stop() { impl_->stop(); }

void Server::wait() {
  for (auto& t : impl_->threads) {
    if (t.joinable()) t.join();
  }
  impl_->threads.clear();
}

const Metrics& Server::metrics() const { return impl_->metrics; }

}  // namespace haarcast::net
