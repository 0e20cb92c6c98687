#include "haarcast/net/render_session.h"

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <utility>

#include "haarcast/wire/encoding_name.h"

namespace haarcast::net {
namespace {

// Stats and BuildProgress are the messages that may be skipped or held: none
// is queued behind this many control messages.
constexpr std::size_t kMaxBacklogForStats = 4;

double secondsBetween(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* fmt, ...) {
  char line[512];
  std::va_list args;
  va_start(args, fmt);
  std::vsnprintf(line, sizeof line, fmt, args);
  va_end(args);
  return line;
}

}  // namespace

RenderSession::RenderSession(const ServerOptions& options, const Catalog& catalog, Metrics& metrics, SessionPort& port,
                             std::string id, Clock::time_point opened)
    : options_(options),
      catalog_(catalog),
      metrics_(metrics),
      port_(port),
      id_(std::move(id)),
      opened_(opened),
      lastMessage_(opened),
      lastStats_(opened) {}

// ------------------------------------------------------------------ messages

void RenderSession::onMessage(std::string_view bytes, bool binary, Clock::time_point now) {
  if (closed_) return;
  lastMessage_ = now;
  const auto& limits = options_.limits;
  if (bytes.size() > limits.maxMessageBytes) {
    fail({v1::ERROR_CODE_MESSAGE_TOO_LARGE,
          "message of " + std::to_string(bytes.size()) + " bytes is over the limit of " +
              std::to_string(limits.maxMessageBytes),
          true},
         CloseCode::TooBig);
    return;
  }
  auto parsed = parseClientMessage(bytes);
  if (auto* e = std::get_if<ProtocolError>(&parsed)) {
    if (!binary) e->message = "text message: " + e->message + " (send protobuf as binary messages)";
    badMessage(std::move(*e));
    return;
  }
  handle(std::get<v1::ClientMessage>(parsed), now);
}

void RenderSession::handle(const v1::ClientMessage& message, Clock::time_point now) {
  if (!hello_ && message.body_case() != v1::ClientMessage::kHello) {
    fail({v1::ERROR_CODE_PROTOCOL_ORDER, "the first message must be a Hello", true});
    return;
  }
  switch (message.body_case()) {
    case v1::ClientMessage::kHello: onHello(message.hello(), now); break;
    case v1::ClientMessage::kPose: onPose(message.pose(), now); break;
    case v1::ClientMessage::kSettings: {
      SessionConfig next = config_;
      if (auto e = applySettings(next, message.settings(), options_.limits, catalog_)) {
        sendError(*e);
        return;
      }
      adopt(std::move(next), false, now);
      break;
    }
    case v1::ClientMessage::kScene: {
      SessionConfig next = config_;
      if (auto e = applySceneChoice(next, message.scene(), catalog_)) {
        sendError(*e);
        return;
      }
      adopt(std::move(next), true, now);
      break;
    }
    case v1::ClientMessage::kPing: port_.send(pongMessage(message.ping().nonce())); break;
    case v1::ClientMessage::BODY_NOT_SET: break;  // parseClientMessage rejects it
  }
}

void RenderSession::badMessage(ProtocolError e) {
  ++badMessages_;
  if (badMessages_ > options_.limits.maxBadMessages) {
    e.message += "; too many bad messages (" + std::to_string(badMessages_) + ")";
    fail(std::move(e));
  } else {
    sendError(e);
  }
}

void RenderSession::onHello(const v1::Hello& hello, Clock::time_point now) {
  if (hello_) {
    sendError({v1::ERROR_CODE_PROTOCOL_ORDER, "a second Hello: send RenderSettings or SceneChoice to change settings", false});
    return;
  }
  const auto& token = options_.token;
  if (!token.empty() && !hello.auth_token().empty() && !tokensEqual(hello.auth_token(), token)) {
    port_.tokenRejected();
    fail({v1::ERROR_CODE_UNAUTHORIZED, "wrong auth_token in Hello", true});
    return;
  }
  auto config = configFromHello(hello, options_.limits, options_.defaults, catalog_);
  if (auto* e = std::get_if<ProtocolError>(&config)) {
    fail(std::move(*e));
    return;
  }
  // Only a valid Hello takes a session slot (a client cannot hold slots by
  // connecting and saying nothing).
  if (auto refused = port_.admit()) {
    fail(std::move(*refused), CloseCode::TryAgainLater);
    return;
  }
  hello_ = true;
  clientName_ = sanitizeForLog(hello.client_name());
  const auto* scene = sceneEntry(std::get<SessionConfig>(config), catalog_);
  {
    std::lock_guard lock(mutex_);
    config_ = std::get<SessionConfig>(std::move(config));
    pose_ = initialPose(scene->camera, scene->poses);
    requested_ = now;
  }
  log(format("hello from \"%s\": %dx%d %s, %.1f fps, level %s%d, %s, %s, scene \"%s\"", clientName_.c_str(),
             config_.width, config_.height, std::string(wire::encodingName(toWire(config_.encoding))).c_str(), config_.fps,
             config_.automaticLevel ? "auto:" : "", config_.level, std::string(methodName(config_.method)).c_str(),
             std::string(backendName(config_.backend)).c_str(), sanitizeForLog(config_.scene).c_str()));
  prepareRenderer();
}

void RenderSession::onPose(const v1::PoseUpdate& update, Clock::time_point now) {
  std::optional<ProtocolError> e;
  bool applied = false;
  {
    std::lock_guard lock(mutex_);
    const auto before = pose_.sequence;
    e = applyPose(pose_, update);
    applied = pose_.sequence != before;
    if (applied) requested_ = now;
  }
  if (e) {
    badMessage(std::move(*e));
    return;
  }
  if (applied) {
    if (update.keyframe() && h264_) {
      std::lock_guard lock(h264_->mutex);
      h264_->keyframeAtPose = update.sequence();
    }
    wantFrame_ = true;
    maybeRender(now);
  }
}

// A changed config: a new renderer when its key changed; the scene's own
// view again when the scene did (the objects are others). An accepted
// SceneChoice is answered with the scene's SceneInfo.
void RenderSession::adopt(SessionConfig next, bool announceScene, Clock::time_point now) {
  // Both read before `next` is moved from. Other objects (another scene or
  // mesh, a mesh turned up another way) start from their own poses; another
  // probe lights the same objects, but meters afresh.
  const bool newObjects = next.scene != config_.scene || next.mesh != config_.mesh || next.up != config_.up;
  const bool newScene = newObjects || next.probe != config_.probe;
  const bool newRenderer = next.rendererKey() != config_.rendererKey();
  {
    std::lock_guard lock(mutex_);
    // Auto exposure starts afresh for another scene or after a fixed spell.
    if (newScene || !next.autoExposure) lastExposure_.reset();
    config_ = std::move(next);
    requested_ = now;  // the next frame answers this change, whatever pose it shows
    if (newObjects) {
      const auto* scene = sceneEntry(config_, catalog_);
      const auto sequence = pose_.sequence;
      pose_ = initialPose(scene->camera, scene->poses);
      pose_.sequence = sequence;  // later poses stay newer
    }
  }
  if (announceScene && welcomed_) {
    port_.send(sceneInfoMessage(config_, catalog_));  // levels not known until its renderer is built
    announcedLevels_.clear();
  }
  // The frame in flight answers the old config: cancelled at its next tile,
  // so the new one starts without waiting for a frame nobody wants.
  if (inFlight_ && current_) current_->cancelled.store(true);
  wantFrame_ = true;
  if (newRenderer) {
    prepareRenderer();
  } else {
    maybeRender(now);
  }
}

// ------------------------------------------------------------------ renderer

void RenderSession::prepareRenderer() {
  renderer_.reset();  // no frames until the renderer for the new config is ready
  heldProgress_.clear();  // an older build's
  port_.prepare(config_);
}

void RenderSession::onBuildProgress(const std::string& key, const BuildProgressUpdate& update) {
  if (closed_ || renderer_ || key != config_.rendererKey()) return;  // ready, or superseded
  heldProgress_ = buildProgressMessage(update);  // the latest wins
  flushBuildProgress();
}

// A client that reads slowly gets the latest progress when it catches up,
// not a queue of stale ones (and is never cut for them: see kMaxControlQueue).
void RenderSession::flushBuildProgress() {
  if (heldProgress_.empty() || closed_ || port_.backlog() >= kMaxBacklogForStats) return;
  port_.send(std::exchange(heldProgress_, std::string()));
}

void RenderSession::onPrepared(const std::string& key, std::shared_ptr<PreparedRenderer> renderer,
                               const std::string& error, Clock::time_point now, v1::ErrorCode code) {
  if (closed_ || key != config_.rendererKey()) return;  // superseded
  heldProgress_.clear();  // the build is over
  if (!renderer) {
    const ProtocolError e{code, "cannot prepare the renderer: " + error, !welcomed_};
    if (e.fatal) {
      fail(e);
    } else {
      sendError(e);
    }
    return;
  }
  renderer_ = std::move(renderer);
  {
    std::lock_guard lock(mutex_);
    requested_ = std::max(requested_, now);  // the build was no frame's time
  }
  const std::vector<int> levels = renderer_->renderer->objectLevels();
  // How each object's pixels are drawn (object_levels.h planObjects), once per renderer.
  const std::vector<std::string> plans = renderer_->renderer->objectPlans();
  if (!plans.empty()) {
    std::string text;
    const Catalog::SceneEntry* scene = catalog_.findScene(config_.scene);
    for (std::size_t k = 0; k < plans.size(); ++k) {
      const bool named = scene && k < scene->objectNames.size() && !scene->objectNames[k].empty();
      text += (k ? "; " : "") + (named ? sanitizeForLog(scene->objectNames[k], 64) : "object " + std::to_string(k)) + ": " + plans[k];
    }
    log("plan: " + text);
  }
  if (!welcomed_) {
    welcomed_ = true;
    lastStats_ = now;
    port_.send(welcomeMessage(config_, catalog_, options_.limits,
                              {id_, renderer_->renderer->objectCount(), renderer_->renderer->deviceName(), levels,
                               renderer_->renderer->rays()}));
  } else if (levels != announcedLevels_) {
    port_.send(sceneInfoMessage(config_, catalog_, levels));
  }
  announcedLevels_ = levels;
  wantFrame_ = true;
  maybeRender(now);
}

// ------------------------------------------------------------------ frames, paced to the fps cap

void RenderSession::onPace(Clock::time_point now) {
  paceArmed_ = false;
  maybeRender(now);
}

void RenderSession::maybeRender(Clock::time_point now) {
  if (!renderer_ || inFlight_ || !wantFrame_ || closed_) return;
  // H.264: every access unit must reach the decoder (each frame depends on
  // the one before), so no frame is rendered while one waits to be sent:
  // the frame slot's latest-wins never drops one. onSent() comes back here.
  if (config_.encoding == FrameEncoding::H264 && frameUnsent_) return;
  if (now < nextFrameAt_) {
    if (!paceArmed_) {
      paceArmed_ = true;
      port_.armPace(nextFrameAt_);
    }
    return;
  }
  wantFrame_ = false;
  inFlight_ = true;
  nextFrameAt_ = now + toDuration(1.0 / std::max(config_.fps, 1e-3));
  current_ = std::make_shared<FrameContext>();
  const std::size_t pixels = static_cast<std::size_t>(config_.width) * static_cast<std::size_t>(config_.height);
  const PreparedRenderer::LastFrame last = renderer_->lastFrame();
  frameProgress_.emplace(now, config_.method, last.stages, last.pixels, pixels);
  FrameOrder order{renderer_, config_.encoding, config_.jpegQuality, pixels, current_, {}};
  if (config_.encoding == FrameEncoding::H264) {
    if (!h264_) h264_ = std::make_shared<H264Stream>();
    order.encode = [stream = h264_, context = current_](const render::Frame& frame) {
      return stream->encode(frame, *context);
    };
  }
  port_.render(std::move(order));
}

std::string H264Stream::encode(const render::Frame& frame, const FrameContext& context) {
  std::lock_guard lock(mutex);
  H264Settings settings = h264Settings(context.config);
  settings.width = frame.width;
  settings.height = frame.height;
  if (!encoder) {
    encoder = std::make_unique<H264Encoder>(settings);  // its first frame is a keyframe
  } else {
    encoder->reconfigure(settings);  // new settings: a keyframe; the same: nothing
  }
  if (keyframeNow || (keyframeAtPose != 0 && context.poseSequence >= keyframeAtPose)) {
    encoder->requestKeyframe();
    keyframeNow = false;
    keyframeAtPose = 0;
  }
  H264AccessUnit unit = encoder->encode(frame.rgba8, frame.width, frame.height);
  if (unit.keyframe) ++keyframes;
  return std::move(unit.annexB);
}

void RenderSession::onCancelled(const FrameContext& context, Clock::time_point now) {
  if (current_.get() != &context) return;  // not the frame in flight (cannot happen: one at a time)
  inFlight_ = false;
  current_.reset();
  frameProgress_.reset();
  if (closed_) return;
  // The frame was wanted for the old request; the new one still wants one.
  wantFrame_ = true;
  maybeRender(now);
}

std::optional<render::FrameRequest> RenderSession::takeRequest(FrameContext& context) {
  std::lock_guard lock(mutex_);
  if (ended_.load()) return std::nullopt;
  context.poseSequence = pose_.sequence;
  context.clientTimeMs = pose_.clientTimeMs;
  context.requested = requested_;
  context.config = config_;
  render::FrameRequest request = frameRequest(pose_, config_);
  if (request.exposure.automatic && lastExposure_) {
    request.exposure.previousStops = lastExposure_;
    request.exposure.adaptation = render::exposureAdaptation(secondsBetween(lastExposureAt_, Clock::now()));
  }
  return request;
}

void RenderSession::onRendered(const FrameContext& context, std::optional<RenderedFrame> rendered,
                               const std::string& error, Clock::time_point now) {
  inFlight_ = false;
  current_.reset();
  frameProgress_.reset();
  if (closed_) return;
  if (!rendered) {
    renderFailed(error, now);
    return;
  }
  lastRenderError_.clear();
  renderErrorRepeats_ = 0;
  if (context.config.autoExposure) {
    std::lock_guard lock(mutex_);
    if (config_.autoExposure && config_.scene == context.config.scene && config_.probe == context.config.probe &&
        config_.mesh == context.config.mesh) {
      lastExposure_ = rendered->frame.exposureStops;
      lastExposureAt_ = now;
    }
  }
  FrameFacts facts;
  facts.stages = rendered->frame.stages;
  facts.stages.push_back({"encode", rendered->encodeSeconds});
  metrics_.addStages(facts.stages);
  periodRenderSeconds_ += rendered->frame.seconds;
  ++periodRendered_;
  facts.sequence = ++frameSequence_;
  facts.poseSequence = context.poseSequence;
  facts.clientTimeMs = context.clientTimeMs;
  facts.serverMs = secondsBetween(context.requested, now) * 1e3;
  const std::size_t payload = rendered->encoded.size();
  if (port_.sendFrame(frameMessage(context.config, rendered->frame, std::move(rendered->encoded), facts), payload)) {
    // The client had not taken the last one yet: latest wins.
    ++framesDropped_;
    metrics_.framesDropped.fetch_add(1);
    if (h264_) {
      // Not expected (maybeRender waits for the slot to empty), but a lost
      // access unit breaks the decoder until the next keyframe: ask for one.
      std::lock_guard lock(h264_->mutex);
      h264_->keyframeNow = true;
    }
  }
  frameUnsent_ = true;
  maybeRender(now);
}

// Every failed frame is counted and said: a new message at once; the same
// one again at most once per kRepeatedErrorSeconds, with how many times it
// recurred since (a broken config must neither flood the client nor go
// silent). onTick says the last repeats when no frame comes to do it.
void RenderSession::renderFailed(const std::string& error, Clock::time_point now) {
  metrics_.renderFailures.fetch_add(1);
  if (error != lastRenderError_) {
    flushRenderErrorRepeats(now, true);
    lastRenderError_ = error;
    lastRenderErrorSent_ = now;
    sendError({v1::ERROR_CODE_RENDER_FAILED, error, false});
    return;
  }
  ++renderErrorRepeats_;
  flushRenderErrorRepeats(now, false);
}

void RenderSession::flushRenderErrorRepeats(Clock::time_point now, bool force) {
  if (renderErrorRepeats_ == 0) return;
  if (!force && secondsBetween(lastRenderErrorSent_, now) < kRepeatedErrorSeconds) return;
  sendError({v1::ERROR_CODE_RENDER_FAILED,
             lastRenderError_ + " (" + std::to_string(renderErrorRepeats_) + " more time" +
                 (renderErrorRepeats_ == 1 ? "" : "s") + " since it was last said)",
             false});
  renderErrorRepeats_ = 0;
  lastRenderErrorSent_ = now;
}

void RenderSession::onSent(bool isFrame, std::size_t payloadBytes, Clock::time_point now) {
  flushBuildProgress();
  if (!isFrame) return;
  frameUnsent_ = false;
  ++framesSent_;
  ++periodFrames_;
  bytesSent_ += payloadBytes;
  metrics_.framesTotal.fetch_add(1);
  metrics_.bytesTotal.fetch_add(payloadBytes);
  if (config_.encoding == FrameEncoding::H264 && !closed_) maybeRender(now);
}

// ------------------------------------------------------------------ errors, timeouts, Stats

void RenderSession::sendError(const ProtocolError& e) {
  if (e.fatal) {
    fail(e);
    return;
  }
  if (closed_) return;
  metrics_.addError(errorLabel(e.code));
  log("error " + errorLabel(e.code) + ": " + sanitizeForLog(e.message, 256));
  port_.send(errorMessage(e));
}

void RenderSession::fail(ProtocolError e, CloseCode code) {
  if (closed_) return;
  closed_ = true;
  e.fatal = true;
  const std::string label = errorLabel(e.code);
  metrics_.addError(label);
  metrics_.addCut(label);
  log("closing, " + label + ": " + sanitizeForLog(e.message, 256));
  port_.close(errorMessage(e), code, closeReason(e.message));
}

void RenderSession::end() {
  closed_ = true;
  ended_.store(true);
  if (current_) current_->cancelled.store(true);  // nobody will read the frame
}

void RenderSession::onTick(Clock::time_point now) {
  if (closed_) return;
  const auto& o = options_;
  if (!hello_ && secondsBetween(opened_, now) > o.handshakeSeconds) {
    metrics_.addTimeout("hello");
    fail({v1::ERROR_CODE_TIMEOUT, format("no Hello within %g s", o.handshakeSeconds), true});
  } else if (secondsBetween(lastMessage_, now) > o.idleSeconds) {
    metrics_.addTimeout("idle");
    fail({v1::ERROR_CODE_TIMEOUT, format("no message for %g s (idle)", o.idleSeconds), true});
  } else {
    flushRenderErrorRepeats(now, false);
    flushBuildProgress();
    sendFrameProgress(now);
    if (welcomed_ && secondsBetween(lastStats_, now) >= o.statsSeconds) sendStats(now);
  }
}

// A frame in flight past kFrameProgressAfterSeconds says how far it is.
// Like Stats it is skipped behind a backlog: the next tick has a newer one.
void RenderSession::sendFrameProgress(Clock::time_point now) {
  if (!inFlight_ || !current_ || !frameProgress_) return;
  const auto update = frameProgress_->poll(current_->stage, now);
  if (!update || port_.backlog() >= kMaxBacklogForStats) return;
  port_.send(frameProgressMessage(*update, config_.width, config_.height));
}

void RenderSession::sendStats(Clock::time_point now) {
  const double period = secondsBetween(lastStats_, now);
  lastStats_ = now;
  StatsFigures s;
  s.framesSent = framesSent_;
  s.framesDropped = framesDropped_;
  s.bytesSent = bytesSent_;
  s.fps = period > 0 ? static_cast<double>(periodFrames_) / period : 0.0;
  s.renderMsMean = periodRendered_ ? periodRenderSeconds_ * 1e3 / static_cast<double>(periodRendered_) : 0.0;
  s.sessions = static_cast<std::uint32_t>(std::max<std::int64_t>(0, metrics_.sessions.load()));
  periodFrames_ = periodRendered_ = 0;
  periodRenderSeconds_ = 0.0;
  if (port_.backlog() < kMaxBacklogForStats) port_.send(statsMessage(s));
}

}  // namespace haarcast::net
