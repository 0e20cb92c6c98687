// One client's session without a socket: the application state machine.
//
//   Hello      → token, config (protocol.h), a session slot (SessionPort::admit),
//                a renderer (prepare) → BuildProgress while it is built → Welcome
//   Settings / SceneChoice → a new config; a new renderer when its key
//                changed (BuildProgress while it is built); SceneInfo for an
//                accepted SceneChoice
//   PoseUpdate → the latest pose wins; a frame is rendered at most once per
//                1/fps (pacing), one at a time
//   Ping       → Pong;  ticks → Hello and idle timeouts, Stats, FrameProgress
//                of a frame in flight past 0.5 s (frame_progress.h)
//
// It emits bytes and requests through a SessionPort: ws_session.cpp
// implements it on a WebSocket, the unit tests with a recorder, so every
// rule here is tested (and fuzzed) without a network. All calls are made on
// one strand, except takeRequest(), which a render worker calls.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include "haarcast/net/frame_progress.h"
#include "haarcast/net/h264_encoder.h"
#include "haarcast/net/messages.h"
#include "haarcast/net/metrics.h"
#include "haarcast/net/protocol.h"
#include "haarcast/net/render_service.h"
#include "haarcast/net/server.h"

namespace haarcast::net {

// What a frame job read when its worker started it; the strand reads it back
// when the frame is done.
struct FrameContext {
  // Set on the strand when the frame is no longer wanted: its session has
  // ended, or a new size, settings or scene replaced the request (a newer
  // pose alone does not: a client that sends poses continuously would never
  // get a frame). The job's `cancelled` reads it from a render worker.
  std::atomic<bool> cancelled{false};
  std::uint64_t poseSequence = 0;
  double clientTimeMs = 0.0;
  // The request this frame answers: its pose received, or a later settings
  // or scene change, or the renderer ready after a build (Frame.server_ms
  // counts from here: a build is not frame time).
  Clock::time_point requested;
  SessionConfig config;
  // Where the render is (the backend moves it on, the session's ticks read
  // it for FrameProgress): the request's StageMark (RenderJob::stage).
  render::StageMark stage;
};

// One frame to render: the transport turns it into a RenderJob whose take()
// is RenderSession::takeRequest(*context).
struct FrameOrder {
  std::shared_ptr<PreparedRenderer> renderer;
  FrameEncoding encoding = FrameEncoding::Jpeg;
  int jpegQuality = 85;
  std::size_t pixels = 0;  // width × height: the job's share of the server's pixel budget
  std::shared_ptr<FrameContext> context;
  // ENCODING_H264: the session's encoder (RenderJob::encode); empty otherwise.
  std::function<std::string(const render::Frame& frame)> encode;
};

// The H.264 stream of one session: its encoder, used by one encode thread at
// a time (a session has one frame in flight) and asked for keyframes from
// the strand, hence the lock.
struct H264Stream {
  std::mutex mutex;
  std::unique_ptr<H264Encoder> encoder;  // made by the first frame
  // A keyframe for the frame answering this pose sequence or a later one
  // (PoseUpdate.keyframe); 0 = none asked for.
  std::uint64_t keyframeAtPose = 0;
  bool keyframeNow = false;  // the next frame, whatever its pose (a frame was lost)
  std::uint64_t keyframes = 0;  // IDRs sent out: for tests and the log

  // One access unit for `frame`, under `config`'s H.264 settings (a change
  // restarts the stream with a keyframe).
  std::string encode(const render::Frame& frame, const FrameContext& context);
};

class SessionPort {
 public:
  virtual ~SessionPort() = default;
  // A control message, sent in order before any frame.
  virtual void send(std::string bytes) = 0;
  // The frame slot: returns true when it replaced a frame not yet sent.
  virtual bool sendFrame(std::string bytes, std::size_t payloadBytes) = 0;
  // Control messages waiting to be written (Stats are skipped behind a backlog).
  virtual std::size_t backlog() const = 0;
  // The end: `error` (a serialised Error) after the messages queued, then a
  // close frame with `code` and `reason`. Nothing is sent after it.
  virtual void close(std::string error, CloseCode code, std::string reason) = 0;
  // Call RenderSession::onPace at `at` (one armed at a time).
  virtual void armPace(Clock::time_point at) = 0;
  // Build or find the renderer for a config → RenderSession::onPrepared,
  // and RenderSession::onBuildProgress while it is built.
  virtual void prepare(const SessionConfig& config) = 0;
  // Render → RenderSession::onRendered(order.context, …).
  virtual void render(FrameOrder order) = 0;
  // A session slot for a valid Hello, or the fatal error saying why not.
  virtual std::optional<ProtocolError> admit() = 0;
  // A Hello carried a wrong auth_token: one guess for the address's limit.
  virtual void tokenRejected() = 0;
  virtual void log(const std::string& line) = 0;
};

class RenderSession {
 public:
  // The same render failure again is re-sent at most this often, with a count.
  static constexpr double kRepeatedErrorSeconds = 1.0;

  RenderSession(const ServerOptions& options, const Catalog& catalog, Metrics& metrics, SessionPort& port,
                std::string id, Clock::time_point opened);

  void onMessage(std::string_view bytes, bool binary, Clock::time_point now);
  // A renderer, or nullptr and why not: `code` is RENDER_FAILED for a build
  // that failed, OVERLOADED for one the server's build queue refused.
  void onPrepared(const std::string& key, std::shared_ptr<PreparedRenderer> renderer, const std::string& error,
                  Clock::time_point now, v1::ErrorCode code = v1::ERROR_CODE_RENDER_FAILED);
  // How far the build of the renderer for `key` has got → BuildProgress.
  // Ignored once the renderer is here, or for a key that is no longer the
  // config's. Like Stats it may wait behind a backlog of control messages,
  // where only the latest waits (sent when the backlog drains).
  void onBuildProgress(const std::string& key, const BuildProgressUpdate& update);
  void onRendered(const FrameContext& context, std::optional<RenderedFrame> rendered, const std::string& error,
                  Clock::time_point now);
  // The job of `context` ended without a frame (cancelled, or its session
  // gone): the next frame may be rendered.
  void onCancelled(const FrameContext& context, Clock::time_point now);
  void onPace(Clock::time_point now);
  void onTick(Clock::time_point now);  // timeouts and Stats
  // A message left the socket. A sent frame lets the next H.264 frame be
  // rendered (its stream never drops an access unit).
  void onSent(bool isFrame, std::size_t payloadBytes, Clock::time_point now = Clock::now());

  // A fatal error: counted, logged, sent, then the close. Idempotent.
  void fail(ProtocolError error, CloseCode code = CloseCode::PolicyError);
  // The transport has gone: jobs not yet started are skipped.
  void end();

  // On a render worker: the latest request, or nullopt when the session has
  // ended (the job is skipped).
  std::optional<render::FrameRequest> takeRequest(FrameContext& context);

  bool closed() const { return closed_; }
  bool welcomed() const { return welcomed_; }
  const std::string& id() const { return id_; }
  const SessionConfig& config() const { return config_; }
  std::uint64_t framesSent() const { return framesSent_; }
  std::uint64_t framesDropped() const { return framesDropped_; }
  std::uint64_t bytesSent() const { return bytesSent_; }

 private:
  void handle(const v1::ClientMessage& message, Clock::time_point now);
  void onHello(const v1::Hello& hello, Clock::time_point now);
  void onPose(const v1::PoseUpdate& update, Clock::time_point now);
  void adopt(SessionConfig next, bool announceScene, Clock::time_point now);
  void prepareRenderer();
  void flushBuildProgress();
  void maybeRender(Clock::time_point now);
  void badMessage(ProtocolError e);
  void renderFailed(const std::string& error, Clock::time_point now);
  // The repeats of lastRenderError_ not yet said: when due, or now (force).
  void flushRenderErrorRepeats(Clock::time_point now, bool force);
  void sendError(const ProtocolError& e);
  void sendStats(Clock::time_point now);
  void sendFrameProgress(Clock::time_point now);
  void log(const std::string& line) { port_.log(id_ + ": " + line); }

  const ServerOptions& options_;
  const Catalog& catalog_;
  Metrics& metrics_;
  SessionPort& port_;
  const std::string id_;

  // Strand state.
  bool hello_ = false, welcomed_ = false, wantFrame_ = false, inFlight_ = false, paceArmed_ = false;
  // The objects' levels the client was last told (Welcome, SceneInfo): a
  // renderer built later with other levels (a new scene, material or level
  // mode) is announced by a SceneInfo that carries them.
  std::vector<int> announcedLevels_;
  bool closed_ = false;
  int badMessages_ = 0;
  std::string clientName_;  // sanitised for the log
  std::shared_ptr<PreparedRenderer> renderer_;
  std::shared_ptr<FrameContext> current_;  // the frame in flight (inFlight_), to cancel
  std::optional<FrameProgressTracker> frameProgress_;  // its progress (FrameProgress), while in flight
  std::shared_ptr<H264Stream> h264_;       // ENCODING_H264 sessions
  bool frameUnsent_ = false;               // a frame waits in the transport's frame slot
  Clock::time_point opened_, lastMessage_, lastStats_, nextFrameAt_{};
  std::uint64_t frameSequence_ = 0, framesSent_ = 0, framesDropped_ = 0, bytesSent_ = 0;
  std::uint64_t periodFrames_ = 0, periodRendered_ = 0;
  double periodRenderSeconds_ = 0.0;
  std::string lastRenderError_;            // the last frame's failure, "" after a frame
  std::uint64_t renderErrorRepeats_ = 0;   // times it recurred since it was last sent
  Clock::time_point lastRenderErrorSent_;
  std::string heldProgress_;               // a BuildProgress waiting for the backlog to drain; "" = none

  // Shared with the render worker (takeRequest): under mutex_. config_ is
  // written on the strand under the lock and read there without it.
  std::mutex mutex_;
  SessionConfig config_;
  PoseState pose_;
  Clock::time_point requested_;  // the latest pose, change or renderer ready (FrameContext::requested)
  std::optional<double> lastExposure_;  // auto exposure: the last frame's, eased from (tonemap.h)
  Clock::time_point lastExposureAt_;
  std::atomic<bool> ended_{false};
};

}  // namespace haarcast::net
