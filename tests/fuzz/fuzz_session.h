// What the protocol and WebSocket fuzz targets share: a RenderSession, the
// socketless application state machine the server runs per client, behind
// a SessionPort that does at once what the server does later — a renderer
// build finishes (or fails) before the next message, a frame renders at its
// size — so that an input can reach every state: welcomed, rendering,
// pacing, a second build, a scene change, a close.
//
// The port checks the session's side of the SessionPort contract and traps
// (a libFuzzer crash) when it is broken:
//   * nothing is sent, built or rendered after close();
//   * one frame in flight at a time;
//   * every message sent parses as a ServerMessage;
//   * a close reason fits a WebSocket close frame (≤ 123 bytes, RFC 6455
//     §5.5) and is whole UTF-8 (§5.5.1);
//   * a log line is one line (client strings are sanitised);
//   * a welcomed session's config stays within the limits.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "haarcast/net/render_session.h"
#include "../unit/net/stub_renderer.h"

namespace haarcast::net::fuzz {

inline void check(bool ok) {
  if (!ok) __builtin_trap();
}

// Whole UTF-8: no sequence cut short, no stray continuation byte.
inline bool wholeUtf8(std::string_view s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    const std::size_t n = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
    if (n == 0 || i + n > s.size()) return false;
    for (std::size_t k = 1; k < n; ++k) {
      if ((static_cast<unsigned char>(s[i + k]) >> 6) != 0x2) return false;
    }
    i += n;
  }
  return true;
}

// The server the fuzz targets stand for: a token ("t"), small frames (a stub
// frame is allocated per render) and short Stats periods.
inline ServerOptions fuzzServerOptions() {
  ServerOptions o;
  o.token = "t";
  o.limits.maxWidth = 64;
  o.limits.maxHeight = 64;
  o.limits.maxMessageBytes = 4096;
  o.defaults.width = 16;
  o.defaults.height = 16;
  o.defaults.level = 4;
  o.handshakeSeconds = 2;
  o.idleSeconds = 30;
  o.statsSeconds = 0.1;
  return o;
}

class FuzzSession : private SessionPort {
 public:
  FuzzSession() : session_(options_, catalog_, metrics_, *this, "fuzz", now_) {}
  // HAARCAST_FUZZ_TRACE=1: how far an input got (to check a seed reaches
  // the states it was written for).
  ~FuzzSession() override {
    if (std::getenv("HAARCAST_FUZZ_TRACE") != nullptr) {
      std::fprintf(stderr, "session: %d messages, %d sent, %d frames, %d builds, welcomed %d, closed %d (%d \"%s\")\n",
                   received_, sent_, frames_, builds_, session_.welcomed() ? 1 : 0, closed_ ? 1 : 0,
                   static_cast<int>(closeCode_), closeReason_.c_str());
    }
  }

  // One message from the client, then what the server would do before the
  // next: the pending build, the frame in flight, the tick and the pace.
  void receive(std::string_view bytes, bool binary) {
    now_ += std::chrono::milliseconds(20);
    ++received_;
    session_.onMessage(bytes, binary, now_);
    settle();
  }

  bool closed() const { return closed_; }
  CloseCode closeCode() const { return closeCode_; }
  const std::string& closeReason() const { return closeReason_; }

 private:
  static Catalog fuzzCatalog() {
    Catalog c;
    render::Pose turned;
    turned.rotateDegrees = {30.0, 0.0, 0.0};
    c.scenes.push_back({"default", {"phong:64", "lambert"}, render::Camera{}, {render::Pose{}, turned}, {"ball", "ring"}});
    c.scenes.push_back({"other", {"ggx:0.3"}, render::Camera{}, {render::Pose{}}, {}});
    c.materials = {"lambert", "phong:64", "ggx:0.3", "steel.binary"};
    c.backends = {Backend::Cpu, Backend::Vulkan};
    return c;
  }

  void settle() {
    // Every third build fails, so the RENDER_FAILED path is reached too.
    // Each reports progress first, under a name with a path and a control
    // character in it (BuildProgress must still parse), and once for a key
    // that is not the config's (ignored).
    if (build_) {
      const SessionConfig config = *build_;
      build_.reset();
      const auto step = static_cast<std::size_t>(received_);
      session_.onBuildProgress(config.rendererKey(), {"visibility /srv/x\x1b/ball", 1, step, 2 * step, 0.5, 1.0});
      session_.onBuildProgress("an older key", {"slices ball", 0, 1, 2, 0.1, 0.1});
      if (++builds_ % 3 == 0) {
        session_.onPrepared(config.rendererKey(), nullptr, "the build failed", now_);
      } else {
        auto prepared = std::make_shared<PreparedRenderer>();
        prepared->key = config.rendererKey();
        prepared->renderer = std::make_unique<StubRenderer>();
        session_.onPrepared(prepared->key, prepared, "", now_);
      }
    }
    if (order_) {
      FrameOrder order = std::move(*order_);
      order_.reset();
      if (auto request = session_.takeRequest(*order.context)) {
        check(request->width == order.context->config.width && request->height == order.context->config.height);
        RenderedFrame rendered;
        rendered.frame = order.renderer->renderer->render(*request);
        rendered.encoded = "frame";
        session_.onRendered(*order.context, std::move(rendered), "", now_);
        session_.onSent(true, 5, now_);
      } else {
        session_.onCancelled(*order.context, now_);
      }
    }
    session_.onTick(now_);
    if (paceAt_ && *paceAt_ <= now_) {
      paceAt_.reset();
      session_.onPace(now_);
    }
    if (session_.welcomed() && !closed_) {
      const SessionConfig& c = session_.config();
      const Limits& l = options_.limits;
      check(c.width >= 1 && c.width <= l.maxWidth && c.height >= 1 && c.height <= l.maxHeight);
      check(c.level >= l.minLevel && c.level <= l.maxLevel);
    }
  }

  static void parses(const std::string& bytes) {
    v1::ServerMessage m;
    check(m.ParseFromString(bytes));
  }

  // SessionPort
  void send(std::string bytes) override {
    check(!closed_);
    parses(bytes);
    ++sent_;
  }
  bool sendFrame(std::string bytes, std::size_t) override {
    check(!closed_);
    parses(bytes);
    ++frames_;
    return false;
  }
  std::size_t backlog() const override { return 0; }
  void close(std::string error, CloseCode code, std::string reason) override {
    check(!closed_);
    parses(error);
    check(reason.size() <= 123 && wholeUtf8(reason));
    closed_ = true;
    closeCode_ = code;
    closeReason_ = std::move(reason);
  }
  void armPace(Clock::time_point at) override { paceAt_ = at; }
  void prepare(const SessionConfig& config) override {
    check(!closed_);
    build_ = config;  // the latest wins, as in the render service
  }
  void render(FrameOrder order) override {
    check(!closed_ && !order_);
    order_ = std::move(order);
  }
  std::optional<ProtocolError> admit() override { return std::nullopt; }
  void tokenRejected() override {}
  void log(const std::string& line) override { check(line.find('\n') == std::string::npos); }

  ServerOptions options_ = fuzzServerOptions();
  Catalog catalog_ = fuzzCatalog();
  Metrics metrics_;
  Clock::time_point now_ = Clock::time_point{} + std::chrono::hours(1);
  bool closed_ = false;
  CloseCode closeCode_ = CloseCode::Normal;
  std::string closeReason_;
  std::optional<Clock::time_point> paceAt_;
  std::optional<SessionConfig> build_;
  std::optional<FrameOrder> order_;
  int builds_ = 0, received_ = 0, sent_ = 0, frames_ = 0;
  RenderSession session_;  // last: it holds references to the members above
};

}  // namespace haarcast::net::fuzz
