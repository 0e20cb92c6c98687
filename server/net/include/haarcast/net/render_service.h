// Many sessions, one renderer per configuration, one device: the render
// service.
//
//   prepare()  gets the renderer for a session's config from an LRU cache,
//              or builds it on the builder thread (slice tables, visibility:
//              seconds), never on an I/O thread. Sessions with the same
//              config share one. Per owner (session) the latest prepare
//              wins: an earlier one still waiting is answered Superseded, and
//              a build nobody waits for any more is dropped (queued) or
//              abandoned (running). The next build is the one whose owner
//              was served longest ago (never served first), so a new session
//              waits at most for the build running when it arrives. At most
//              Options::maxQueuedBuilds builds wait across the server;
//              beyond that prepare is Refused. While a build runs, its
//              progress goes to every prepare waiting for it (at most one
//              update per Options::progressIntervalSeconds, plus one at
//              each new stage), and a prepare that joins it later gets the
//              latest at once; a cached renderer has none.
//   submit()   queues one frame job. Jobs start in FIFO order on
//              Options::workers threads, and each session keeps at most one
//              job queued or running, so the queue is a round robin over the
//              sessions that want a frame: a fast client cannot starve a slow
//              one. Frames of different sessions render at once, up to the
//              workers and the server's pixel budget; a renderer that cannot
//              render concurrently (Vulkan) renders one frame at a time.
//
// A job asks its session for the request when the worker starts it (not when
// it was queued), so the frame answers the latest pose. A job is cancelled
// when its `cancelled` says so or the service stops: before it starts, or
// mid-frame at the renderer's next tile (CPU) or batch (Vulkan) boundary.
// Encoding runs on a separate small pool, so the device is not idle while a
// frame is compressed.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "haarcast/net/build_progress.h"
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
// A builder that may stop early and says how far it is. `abandoned()` turns
// true once nobody waits for the build any more (every waiter superseded or
// withdrawn) or the service stops; the builder polls it between its
// precompute stages (its RenderProgress callback is a good place) and then
// throws anything: the build ends quietly, unanswered. `progress` takes the
// builder's render::RenderProgress reports (stage, done, total) for the
// sessions that wait; it is cheap to call often (it throttles) and never
// blocks on a client.
using AbandonableRendererBuilder = std::function<std::shared_ptr<PreparedRenderer>(
    const SessionConfig& config, const std::function<bool()>& abandoned, const render::RenderProgress& progress)>;
// A builder that can neither stop early nor report progress, as one that can.
AbandonableRendererBuilder asAbandonable(RendererBuilder builder);

struct RenderedFrame {
  render::Frame frame;
  std::string encoded;     // the Frame's data in the session's encoding
  double encodeSeconds = 0.0;
  double queuedSeconds = 0.0;  // submit → worker start
};

struct RenderJob {
  std::shared_ptr<PreparedRenderer> renderer;
  // Called on the worker when it starts: the latest request, or nullopt when
  // the session has gone (the job ends as cancelled).
  std::function<std::optional<render::FrameRequest>()> take;
  // The frame's width × height, as the session's config says at submit: the
  // share of the server's pixel budget the job waits for and holds while it
  // renders. 0 = unknown: the job does not wait, and holds the size of the
  // request take() returns.
  std::size_t pixels = 0;
  // Polled before the job starts and at every tile or batch boundary of its
  // render (and possibly under the service's lock): cheap, thread-safe and
  // never calling into the service. true = the session has gone or the pose
  // is superseded. Empty = only stop() cancels.
  std::function<bool()> cancelled;
  // The encoding of the finished frame.
  FrameEncoding encoding = FrameEncoding::Jpeg;
  int jpegQuality = 85;
  // When set, encodes the finished frame instead of `encoding`'s stateless
  // encoder: a session's own stateful encoder (H.264). Called on an encode
  // thread; a session has one job at a time, so its frames are encoded in
  // order, one at a time. Throws like the encoders.
  std::function<std::string(const render::Frame& frame)> encode;
  // Called once, on a service thread, with the frame or an error message
  // (a frame over Options::maxSessionPixels is an error naming the limit).
  std::function<void(std::optional<RenderedFrame>, std::string error)> done;
  // Called once instead of `done` when the job ends without a frame and
  // without an error: cancelled before or during its render, or take()
  // returned nullopt. On a service thread; may be empty.
  std::function<void()> onCancelled;
};

// How a prepare() ended.
enum class PrepareStatus {
  Ready,       // `renderer` is set
  Failed,      // the build threw: `error` says why
  Refused,     // the server's build queue is full: `error` names the limit
  Superseded,  // a newer prepare() from the same owner replaced this one
};
struct PrepareOutcome {
  PrepareStatus status = PrepareStatus::Failed;
  std::shared_ptr<PreparedRenderer> renderer;
  std::string error;
};

class RenderService {
 public:
  struct Options {
    std::size_t maxRenderers = 4;  // LRU bound of the cache (in use ones stay alive while used)
    // Render threads: the frames of this many sessions render at once (a
    // renderer that cannot render concurrently, Vulkan, one at a time).
    int workers = 4;
    int encoders = 2;  // encode threads
    // One frame's width × height per session; a larger frame is an error
    // naming this limit. By default the protocol's largest frame.
    std::size_t maxSessionPixels = static_cast<std::size_t>(Limits{}.maxWidth) * static_cast<std::size_t>(Limits{}.maxHeight);
    // The pixels rendering at once across the server: a job waits while
    // its pixels would not fit, and a job larger than the budget runs
    // alone. 0 = no budget. By default two of the largest frames.
    std::size_t serverPixelBudget = 2 * maxSessionPixels;
    // Renderer builds waiting (not running) across the server; a prepare()
    // that needs one more is Refused.
    std::size_t maxQueuedBuilds = 8;
    // A running build's progress goes to its waiters at most this often,
    // besides one update at each new stage (build_progress.h): about 4 a
    // second, enough for a moving display, few enough for any link.
    double progressIntervalSeconds = 0.25;
  };

  // Throws std::invalid_argument naming an option out of range.
  RenderService(RendererBuilder builder, Options options, Metrics& metrics);
  RenderService(AbandonableRendererBuilder builder, Options options, Metrics& metrics);
  ~RenderService();  // stop()
  RenderService(const RenderService&) = delete;
  RenderService& operator=(const RenderService&) = delete;

  using PrepareDone = std::function<void(PrepareOutcome)>;
  // Called with each progress update of the build this prepare waits for:
  // on the builder thread, or on the caller's thread from within prepare()
  // (the latest update of a build already running), never under the
  // service's lock. It must be quick and must not block or call into the
  // service: a session posts the update to its strand. Every update comes
  // before `done`, except the one from within prepare(), which may race a
  // build that finishes meanwhile; a session ignores progress once it has
  // its renderer.
  using ProgressSink = std::function<void(const BuildProgressUpdate&)>;
  // done(outcome) once, on a service thread, or on the caller's thread when
  // the answer is immediate (cached, superseded, refused). `owner` names
  // the session: its newer prepare supersedes this one ("" = nobody's:
  // never superseded). `progress` (may be empty): see ProgressSink; a
  // cached renderer, or a build that reports nothing, gives none.
  void prepare(const SessionConfig& config, const std::string& owner, PrepareDone done, ProgressSink progress = {});
  // The owner's waiting prepare, if any, is dropped unanswered (its session
  // has gone); a build then waited for by nobody is dropped or abandoned.
  void withdraw(const std::string& owner);
  using PrepareCallback = std::function<void(std::shared_ptr<PreparedRenderer>, std::string error)>;
  // Nobody's prepare: done(renderer, "") or done(nullptr, error).
  void prepare(const SessionConfig& config, PrepareCallback done);

  void submit(RenderJob job);

  // For tests, /metrics and /readyz: jobs waiting now, builds waiting now,
  // the pixels of the frames rendering now, and whether a job waits for the
  // server's pixel budget (or the budget is spent).
  std::size_t queued() const;
  std::size_t queuedBuilds() const;
  std::size_t pixelsInFlight() const;
  bool atPixelBudget() const;

  // Cancels the renders in progress (they end at their next tile or batch
  // boundary, as cancelled) and abandons a running build, drops the queued
  // jobs and prepares (their callbacks destroyed uncalled), joins the
  // threads. Idempotent.
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace haarcast::net
