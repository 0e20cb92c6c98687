#include "haarcast/client/session.h"

#include <cctype>
#include <deque>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <span>

#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include "haarcast/client/build_progress.h"
#include "haarcast/client/frame_image.h"
#include "haarcast/wire/frame_codec.h"
#include "haarcast/wire/frame_decode.h"

namespace haarcast::client {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using Clock = std::chrono::steady_clock;

struct Session::Impl : std::enable_shared_from_this<Session::Impl> {
  Impl(asio::io_context& io, std::size_t clientIndex, SessionConfig sessionConfig, SessionStats& sessionStats,
       FrameCallback frameCallback, MessageCallback messageCallback, BuildCallback buildCallback)
      : index(clientIndex),
        config(std::move(sessionConfig)),
        stats(sessionStats),
        onFrame(std::move(frameCallback)),
        onMessage(std::move(messageCallback)),
        onBuild(std::move(buildCallback)),
        resolver(io),
        ws(io),
        watchdog(io),
        keepalive(io) {}

  std::size_t index;
  SessionConfig config;
  SessionStats& stats;
  FrameCallback onFrame;
  MessageCallback onMessage;
  BuildCallback onBuild;
  std::function<void()> answered;  // Session::start's, until called

  tcp::resolver resolver;
  websocket::stream<beast::tcp_stream> ws;
  asio::steady_timer watchdog;
  asio::steady_timer keepalive;
  std::uint64_t pingNonce = 0;
  beast::flat_buffer readBuffer;
  http::response<http::string_body> upgradeResponse;
  std::deque<std::string> writes;  // serialized ClientMessages; front() is in flight
  bool writing = false;

  v1::Welcome welcome;
  bool welcomed = false;
  bool closing = false;  // we started the close handshake (or gave up)
  std::uint64_t nextPose = 1;  // sequence of the next pose to send
  bool timeUp = false;         // --duration has passed: no new poses
  std::map<std::uint64_t, double> outstanding;  // pose sequence → sent at (ms since run start)
  // Every frame of the session in order: an H.264 frame refers to the ones
  // before it, so the decoder sees each one, counted or not.
  FrameDecoder decoder;
  bool keyframeWanted = false;     // the next pose asks for a keyframe (PoseUpdate.keyframe)
  std::uint64_t keyframeAskedAt = 0;  // the pose that last asked; 0: none outstanding
  std::string phase = "connecting";
  std::string lastFrameStage;     // the last FrameProgress that moved (onFrameProgress)
  double lastFrameFraction = 0.0;

  double nowMs() const {
    return std::chrono::duration<double, std::milli>(Clock::now() - config.runStart).count();
  }
  std::string who() const { return "client " + std::to_string(index) + ": "; }

  // The session ends here on any failure, once: the reason is kept for the
  // summary and the exit code, and the socket is closed.
  // Once: the server has answered, or the session is over.
  void markAnswered() {
    if (!answered) return;
    const auto callback = std::move(answered);
    answered = nullptr;
    callback();
  }

  void fail(const std::string& why) {
    markAnswered();
    if (stats.failure.empty()) {
      stats.failure = why;
      onMessage(who() + why);
    }
    closing = true;
    watchdog.cancel();
    keepalive.cancel();
    beast::error_code ignored;
    beast::get_lowest_layer(ws).socket().close(ignored);
  }

  // The server closes sessions that send nothing for a while (its idle
  // timeout), and a client waiting for a slow frame sends nothing: a Ping
  // every 15 s keeps such a session open.
  void scheduleKeepalive() {
    keepalive.expires_after(std::chrono::seconds(15));
    keepalive.async_wait([self = shared_from_this()](beast::error_code ec) {
      if (ec || self->closing) return;
      v1::ClientMessage ping;
      ping.mutable_ping()->set_nonce(++self->pingNonce);
      self->send(ping);
      self->scheduleKeepalive();
    });
  }

  void armWatchdog(const std::string& waitingFor) {
    phase = waitingFor;
    watchdog.expires_after(std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(config.timeoutSeconds)));
    watchdog.async_wait([self = shared_from_this()](beast::error_code ec) {
      if (ec || self->closing) return;  // cancelled: something arrived in time
      self->fail("timed out after " + std::to_string(self->config.timeoutSeconds) + " s waiting for " + self->phase);
    });
  }

  void start() {
    armWatchdog("the connection to " + config.url.host + ":" + config.url.port);
    resolver.async_resolve(config.url.host, config.url.port,
                           [self = shared_from_this()](beast::error_code ec, tcp::resolver::results_type results) {
                             self->onResolve(ec, std::move(results));
                           });
  }

  void onResolve(beast::error_code ec, tcp::resolver::results_type results) {
    if (closing) return;
    if (ec) return fail("cannot resolve host \"" + config.url.host + "\": " + ec.message());
    beast::get_lowest_layer(ws).async_connect(
        results, [self = shared_from_this()](beast::error_code e, const tcp::endpoint&) { self->onConnect(e); });
  }

  void onConnect(beast::error_code ec) {
    if (closing) return;
    if (ec) {
      return fail("cannot connect to " + config.url.host + ":" + config.url.port + ": " + ec.message() +
                  (ec == asio::error::connection_refused ? " (is `haarcast serve` running on that port?)" : ""));
    }
    beast::get_lowest_layer(ws).socket().set_option(tcp::no_delay(true));
    ws.set_option(websocket::stream_base::decorator([token = config.token](websocket::request_type& req) {
      req.set(http::field::user_agent, "haarcast-client");
      if (!token.empty()) req.set(http::field::authorization, "Bearer " + token);
    }));
    // Frames can be large (raw 1024² is 4 MiB); the default 16 MiB limit
    // would refuse 4K raw frames with a confusing error.
    ws.read_message_max(std::uint64_t{256} << 20);
    ws.binary(true);
    armWatchdog("the WebSocket upgrade");
    ws.async_handshake(upgradeResponse, config.url.host + ":" + config.url.port, config.url.target,
                       [self = shared_from_this()](beast::error_code e) { self->onHandshake(e); });
  }

  void onHandshake(beast::error_code ec) {
    if (closing) return;
    if (ec == websocket::error::upgrade_declined) {
      const auto status = upgradeResponse.result_int();
      std::string why = "the server refused the WebSocket upgrade at " + config.url.target + ": HTTP " +
                        std::to_string(status) + " " + std::string(upgradeResponse.reason());
      if (status == 401 || status == 403) why += config.token.empty() ? " (the server wants --token)" : " (wrong --token?)";
      std::string body = upgradeResponse.body().substr(0, 200);
      while (!body.empty() && std::isspace(static_cast<unsigned char>(body.back()))) body.pop_back();
      if (!body.empty()) why += ": " + body;
      return fail(why);
    }
    if (ec) return fail("WebSocket upgrade failed: " + ec.message());
    // From here the watchdog times the frames (and names what was awaited);
    // the stream's own timeout only bounds the closing handshake, so that a
    // server that never answers our close cannot hang the client.
    beast::get_lowest_layer(ws).expires_never();
    websocket::stream_base::timeout timeouts{};
    timeouts.handshake_timeout = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double>(config.timeoutSeconds));
    timeouts.idle_timeout = websocket::stream_base::none();
    timeouts.keep_alive_pings = false;
    ws.set_option(timeouts);

    v1::ClientMessage hello;
    *hello.mutable_hello() = config.hello;
    hello.mutable_hello()->set_auth_token(config.token);
    send(hello);
    armWatchdog("Welcome");
    doRead();
  }

  void send(const v1::ClientMessage& message) {
    writes.push_back(message.SerializeAsString());
    if (!writing) doWrite();
  }

  void doWrite() {
    writing = true;
    ws.async_write(asio::buffer(writes.front()), [self = shared_from_this()](beast::error_code ec, std::size_t) {
      self->writing = false;
      if (self->closing) return;
      if (ec) return self->fail("send failed: " + ec.message());
      self->writes.pop_front();
      if (!self->writes.empty()) self->doWrite();
    });
  }

  void doRead() {
    ws.async_read(readBuffer, [self = shared_from_this()](beast::error_code ec, std::size_t bytes) {
      self->onRead(ec, bytes);
    });
  }

  void onRead(beast::error_code ec, std::size_t bytes) {
    if (ec) {
      if (closing) return;  // our own close, or a failure already reported
      if (ec == websocket::error::closed) {
        const auto& reason = ws.reason();
        return fail("the server closed the session after " + std::to_string(stats.frames) + " of " +
                    std::to_string(config.frames) + " frames (close code " + std::to_string(reason.code) +
                    (reason.reason.empty() ? "" : ": " + std::string(reason.reason.c_str())) + ")");
      }
      return fail("connection lost after " + std::to_string(stats.frames) + " of " + std::to_string(config.frames) +
                  " frames: " + ec.message());
    }
    v1::ServerMessage message;
    const auto data = readBuffer.cdata();
    if (!message.ParseFromArray(data.data(), static_cast<int>(data.size()))) {
      return fail("the server sent " + std::to_string(bytes) + " bytes that are not a haarcast.v1.ServerMessage");
    }
    readBuffer.consume(readBuffer.size());
    markAnswered();
    switch (message.body_case()) {
      case v1::ServerMessage::kWelcome: onWelcome(message.welcome()); break;
      case v1::ServerMessage::kFrame: onFrameMessage(message.frame(), bytes); break;
      case v1::ServerMessage::kStats:
        stats.lastStats = std::pair{nowMs() / 1000.0, message.stats().frames_sent()};
        if (!stats.firstStats) stats.firstStats = stats.lastStats;
        stats.serverSessions = message.stats().sessions();
        break;
      case v1::ServerMessage::kError: onError(message.error()); break;
      case v1::ServerMessage::kPong: break;
      case v1::ServerMessage::kSceneInfo: break;  // this client changes no scene after Hello
      case v1::ServerMessage::kBuildProgress: onBuildProgress(message.build_progress()); break;
      case v1::ServerMessage::kFrameProgress: onFrameProgress(message.frame_progress()); break;
      case v1::ServerMessage::BODY_NOT_SET:
        // A newer server's message type arrives as unknown fields: ignored,
        // as the protocol's "fields are only ever added" asks. Nothing at
        // all is a broken server.
        if (message.GetReflection()->GetUnknownFields(message).empty()) {
          return fail("the server sent a ServerMessage with no body");
        }
        break;
    }
    if (!closing) doRead();
  }

  // The renderer is being built: shown, and proof that the server works on
  // it, so the wait (for Welcome, or the next frame) starts again.
  void onBuildProgress(const v1::BuildProgress& progress) {
    if (onBuild) onBuild(index, &progress);
    armWatchdog(welcomed ? phase : "Welcome (the renderer build last reported: " + buildProgressText(progress) + ")");
  }

  // A long frame moves on: the wait for it starts again. Only when it has
  // moved (another stage, a larger fraction): a frame stuck in one place
  // still runs into the watchdog, however many of these the server sends.
  void onFrameProgress(const v1::FrameProgress& progress) {
    if (progress.stage() == lastFrameStage && progress.fraction() <= lastFrameFraction) return;
    lastFrameStage = progress.stage();
    lastFrameFraction = progress.fraction();
    armWatchdog(phase);
  }

  void onWelcome(const v1::Welcome& w) {
    if (welcomed) return fail("the server sent a second Welcome");
    if (onBuild) onBuild(index, nullptr);
    welcome = w;
    welcomed = true;
    scheduleKeepalive();
    if (w.protocol_version() != v1::PROTOCOL_VERSION_1) {
      onMessage(who() + "the server speaks protocol version " + std::to_string(w.protocol_version()) +
                ", this client version 1");
    }
    fillWindow();
  }

  // The sequence of the last pose to send: fixed by --frames, or, with
  // --duration, whatever was sent when the time ran out.
  std::uint64_t lastPose() const {
    if (config.durationSeconds <= 0.0) return config.warmup + config.frames;
    return timeUp ? nextPose - 1 : std::numeric_limits<std::uint64_t>::max();
  }
  bool measured(std::uint64_t sequence) const { return sequence > config.warmup; }

  void fillWindow() {
    if (config.durationSeconds > 0.0 && nextPose > config.warmup + 1 &&
        nowMs() / 1000.0 - stats.firstPoseSeconds >= config.durationSeconds) {
      timeUp = true;
    }
    while (nextPose <= lastPose() && outstanding.size() < config.inFlight) {
      v1::ClientMessage message;
      auto* pose = message.mutable_pose();
      // Warm-up poses replay the start of the path; measured pose i is path pose i.
      const std::uint64_t pathIndex = measured(nextPose) ? nextPose - 1 - config.warmup : nextPose - 1;
      *pose = config.path->at(static_cast<std::size_t>(pathIndex % config.frames), static_cast<std::size_t>(config.frames));
      pose->set_sequence(nextPose);
      if (keyframeWanted) {
        // The request rides on the next pose of the path, so the path's
        // numbering and the closed loop stay as they are.
        pose->set_keyframe(true);
        keyframeWanted = false;
        keyframeAskedAt = nextPose;
        ++stats.keyframeRequests;
      }
      const double sentMs = nowMs();
      pose->set_client_time_ms(sentMs);
      outstanding[nextPose] = sentMs;
      if (nextPose == config.warmup + 1) stats.firstPoseSeconds = sentMs / 1000.0;
      ++nextPose;
      if (measured(nextPose - 1)) ++stats.posesSent;
      send(message);
    }
    armWatchdog("the frame answering pose " + std::to_string(outstanding.empty() ? 0 : outstanding.begin()->first));
  }

  bool inspects() const { return config.checkNotBlank || config.maxClipped >= 0.0; }

  // H.264 frames through the session's decoder, every one and in order.
  // A frame that does not decode (a delta frame without its keyframe) is
  // counted, and the next pose asks for a keyframe: unless a request is
  // already on its way, i.e. the failing frame answers a pose sent before
  // the one that asked (the keyframe answers that one or a later pose).
  std::optional<wire::Rgba8Image> decodeInOrder(const v1::Frame& frame) {
    const std::span<const std::uint8_t> data(reinterpret_cast<const std::uint8_t*>(frame.data().data()),
                                             frame.data().size());
    try {
      wire::Rgba8Image image = decoder.decode(frame.encoding(), data, frame.width(), frame.height());
      keyframeAskedAt = 0;
      return image;
    } catch (const std::runtime_error& e) {
      ++stats.undecodedFrames;
      const bool asked = keyframeWanted || (keyframeAskedAt != 0 && frame.pose_sequence() < keyframeAskedAt);
      if (!asked) keyframeWanted = true;
      onMessage(who() + "frame " + std::to_string(frame.sequence()) + " (pose " +
                std::to_string(frame.pose_sequence()) + ") did not decode: " + e.what() +
                (asked ? "; a keyframe is on its way" : "; the next pose asks for a keyframe"));
      return std::nullopt;
    }
  }

  void onFrameMessage(const v1::Frame& frame, std::size_t wireBytes) {
    lastFrameStage.clear();  // the next frame's progress starts afresh
    lastFrameFraction = 0.0;
    // Decoded before anything else, so that warm-up and extra frames reach
    // the decoder too; only when a frame is inspected or recorded at all.
    std::optional<wire::Rgba8Image> h264;
    bool undecoded = false;
    if (frame.encoding() == v1::ENCODING_H264 && (inspects() || !config.outDir.empty())) {
      h264 = decodeInOrder(frame);
      undecoded = !h264;
    }
    const auto it = outstanding.find(frame.pose_sequence());
    if (!welcomed || it == outstanding.end()) {
      ++stats.extraFrames;  // e.g. a first frame for pose 0, or a repeat
      return;
    }
    const double latency = nowMs() - it->second;
    // "Latest wins": the poses before this one were skipped by the server.
    for (auto old = outstanding.begin(); old != it; old = outstanding.erase(old)) {
      if (measured(old->first)) ++stats.dropped;
    }
    outstanding.erase(it);
    if (!measured(frame.pose_sequence())) {
      fillWindow();
      return;
    }

    ++stats.frames;
    stats.payloadBytes += frame.data().size();
    stats.wireBytes += wireBytes;
    stats.latencyMs.push_back(latency);
    stats.serverMs.push_back(frame.server_ms());
    for (const auto& t : frame.timings()) stats.stageMs[t.name()].push_back(t.ms());
    stats.lastFrameSeconds = nowMs() / 1000.0;

    if (!undecoded && !recordAndCheck(frame, std::move(h264))) return;
    onFrame({index, frame.pose_sequence(), latency, frame.data().size()});

    fillWindow();
    if (nextPose > lastPose() && outstanding.empty()) finish();
  }

  // Writes the frame under --out and checks it is not blank; false when the
  // session failed doing so. `decoded`: the H.264 picture, decoded in order.
  bool recordAndCheck(const v1::Frame& frame, std::optional<wire::Rgba8Image> decoded) {
    const auto encoding = frame.encoding();
    // Raw and H.264 frames are written decoded (PAM, PNG): their bytes alone are no viewable file.
    const bool raw = encoding == v1::ENCODING_RAW_RGBA8;
    const bool h264 = encoding == v1::ENCODING_H264;
    stats.lastExposureStops = frame.exposure_stops();
    const bool inspect = inspects();
    if (!inspect && config.outDir.empty()) return true;
    try {
      wire::Rgba8Image image;
      if (decoded) {
        image = std::move(*decoded);
      } else if (inspect || raw) {
        image = wire::decodeFrame(encoding, frame.data(), frame.width(), frame.height());
      }
      if (inspect) {
        const PixelStats px = pixelStats(image);
        stats.clippedFractionMax = std::max(stats.clippedFractionMax, px.clippedFraction);
        if (config.maxClipped >= 0.0 && px.clippedFraction > config.maxClipped) {
          ++stats.clippedFrames;
          onMessage(who() + "frame " + std::to_string(frame.sequence()) + " (pose " +
                    std::to_string(frame.pose_sequence()) + ") is blown out: " +
                    std::to_string(100.0 * px.clippedFraction) + "% of its pixels at 255 (--max-clipped " +
                    std::to_string(100.0 * config.maxClipped) + "%), exposure " +
                    std::to_string(frame.exposure_stops()) + " stops");
        }
      }
      if (config.checkNotBlank) {
        const PixelStats px = pixelStats(image);
        if (isBlank(px)) {
          ++stats.blankFrames;
          onMessage(who() + "frame " + std::to_string(frame.sequence()) + " (pose " +
                    std::to_string(frame.pose_sequence()) + ") is blank: luma stddev " +
                    std::to_string(px.stddevLuma) + " < " + std::to_string(kBlankStddevLuma));
        }
      }
      if (!config.outDir.empty()) {
        char name[32];
        std::snprintf(name, sizeof name, "frame-%06llu", static_cast<unsigned long long>(stats.frames));
        const auto path = std::filesystem::path(config.outDir) / (name + encodingFileExtension(encoding));
        std::ofstream out(path, std::ios::binary);
        if (raw) {
          const auto pam = encodePam(image);
          out.write(reinterpret_cast<const char*>(pam.data()), static_cast<std::streamsize>(pam.size()));
        } else if (h264) {
          const std::string png = wire::encodePng(image.pixels, image.width, image.height);
          out.write(png.data(), static_cast<std::streamsize>(png.size()));
        } else {
          out.write(frame.data().data(), static_cast<std::streamsize>(frame.data().size()));
        }
        if (!out) {
          fail("cannot write " + path.string());
          return false;
        }
      }
    } catch (const std::exception& e) {
      fail("frame " + std::to_string(frame.sequence()) + ": " + e.what());
      return false;
    }
    return true;
  }

  void onError(const v1::Error& error) {
    ++stats.errors;
    const std::string text = "server error " + v1::ErrorCode_Name(error.code()) + ": " + error.message();
    if (error.fatal()) return fail(text);
    onMessage(who() + text + " (not fatal)");
  }

  void finish() {
    closing = true;
    watchdog.cancel();
    keepalive.cancel();
    ws.async_close(websocket::close_code::normal, [self = shared_from_this()](beast::error_code) {
      // The server may already be gone after answering; the frames are in.
      beast::error_code ignored;
      beast::get_lowest_layer(self->ws).socket().close(ignored);
    });
  }
};

Session::Session(asio::io_context& io, std::size_t index, SessionConfig config, SessionStats& stats,
                 FrameCallback onFrame, MessageCallback onMessage, BuildCallback onBuild)
    : impl_(std::make_shared<Impl>(io, index, std::move(config), stats, std::move(onFrame), std::move(onMessage),
                                   std::move(onBuild))) {}

void Session::start(std::function<void()> answered) {
  impl_->answered = std::move(answered);
  impl_->start();
}

const v1::Welcome& Session::welcome() const { return impl_->welcome; }

}  // namespace haarcast::client
