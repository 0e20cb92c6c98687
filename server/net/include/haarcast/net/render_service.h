// Many sessions, one renderer per configuration, one device: the render
// service.
//
//   prepare()  gets the renderer for a session's config from an LRU cache,
//              or builds it on the builder thread (slice tables, visibility:
//              seconds), never on an I/O thread. Sessions with the same
//              config share one.
//   submit()   queues one frame job. Jobs run on the worker thread(s) in
//              FIFO order, and each session keeps at most one job queued or
//              running, so the queue is a round robin over the sessions that
//              want a frame: a fast client cannot starve a slow one.
//
// A job asks its session for the request when the worker starts it (not when
// it was queued), so the frame answers the latest pose. Renderers are not
// thread-safe: each is locked while it renders. Encoding runs on a separate
// small pool, so the device is not idle while a frame is compressed.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "haarcast/net/metrics.h"
#include "haarcast/net/protocol.h"
#include "haarcast/render/renderer.h"

namespace haarcast::net {

// A prepared renderer, shared by the sessions with the same rendererKey().
struct PreparedRenderer {
  std::string key;
  std::unique_ptr<render::Renderer> renderer;
};

// Builds the renderer for a config; runs on the builder thread. Throws with
// a message naming what was wrong.
using RendererBuilder = std::function<std::shared_ptr<PreparedRenderer>(const SessionConfig& config)>;

struct RenderedFrame {
  render::Frame frame;
  std::string encoded;     // the Frame's data in the session's encoding
  double encodeSeconds = 0.0;
  double queuedSeconds = 0.0;  // submit → worker start
};

struct RenderJob {
  std::shared_ptr<PreparedRenderer> renderer;
  // Called on the worker when it starts: the latest request, or nullopt when
  // the session has gone (the job is skipped).
  std::function<std::optional<render::FrameRequest>()> take;
  // The encoding of the finished frame.
  FrameEncoding encoding = FrameEncoding::Jpeg;
  int jpegQuality = 85;
  // Called once, on a service thread, with the frame or an error message.
  std::function<void(std::optional<RenderedFrame>, std::string error)> done;
};

class RenderService {
 public:
  struct Options {
    std::size_t maxRenderers = 4;  // LRU bound of the cache (in use ones stay alive while used)
    int workers = 1;               // render threads: one per device
    int encoders = 2;              // encode threads
  };

  RenderService(RendererBuilder builder, Options options, Metrics& metrics);
  ~RenderService();  // stop()
  RenderService(const RenderService&) = delete;
  RenderService& operator=(const RenderService&) = delete;

  using PrepareCallback = std::function<void(std::shared_ptr<PreparedRenderer>, std::string error)>;
  // done(renderer, "") or done(nullptr, error), on a service thread (or on
  // the caller's thread when the renderer is already cached).
  void prepare(const SessionConfig& config, PrepareCallback done);

  void submit(RenderJob job);

  // Jobs waiting now (for tests and /metrics).
  std::size_t queued() const;

  // Finishes the jobs in progress, drops the rest (their callbacks are
  // destroyed uncalled), joins the threads. Idempotent.
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace haarcast::net
