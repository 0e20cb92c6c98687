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
//              workers and the server's pixel budget. Renderers that cannot
//              render concurrently (Vulkan) take turns per device: one frame
//              at a time on a device, and a job whose device is busy leaves
//              its worker free for another session's job.
//
// A frame past Options::frameDeadlineSeconds is abandoned (frame_workers.h):
// its session's `done` gets an error naming the stage it was stuck in and
// its device, its pixels leave the budget, its worker is replaced (the
// stuck thread is left behind, detached) and its device turns unhealthy:
// later jobs for it fail at once, naming the device and why, until every
// frame abandoned on it has returned.
//
// A job asks its session for the request when the worker starts it (not when
// it was queued), so the frame answers the latest pose. A job is cancelled
// when its `cancelled` says so or the service stops: before it starts, or
// mid-frame at the renderer's next tile (CPU) or batch (Vulkan) boundary.
// Encoding runs on a separate small pool, so the device is not idle while a
// frame is compressed.
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>
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

  // The stages of its last frame, any session's, with their times and the
  // frame's pixels: the weights of a frame's progress (frame_progress.h).
  // Empty before its first frame.
  struct LastFrame {
    std::vector<render::StageTime> stages;
    std::size_t pixels = 0;
  };
  LastFrame lastFrame() const {
    std::lock_guard lock(lastFrameMutex_);
    return lastFrame_;
  }
  void setLastFrame(LastFrame frame) {
    std::lock_guard lock(lastFrameMutex_);
    lastFrame_ = std::move(frame);
  }

 private:
  mutable std::mutex lastFrameMutex_;
  LastFrame lastFrame_;
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
  // Where the frame is while it renders (the request's StageMark): the
  // session's, which shows a long frame's progress to its client; empty =
  // the service's own. The frame deadline reads it too.
  std::shared_ptr<render::StageMark> stage;
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

// A device the service has rendered on, named by its renderers' backend()
// and deviceName(): renderers of one backend on one device share its busy
// flag and its health.
struct DeviceStatus {
  std::string backend;  // "cpu" | "vulkan"
  std::string device;   // Renderer::deviceName()
  bool healthy = true;  // no frame abandoned on it is still stuck
  std::string reason;   // unhealthy: the last abandoned frame ("a frame abandoned after 30 s in stage …")
};

// A render thread left behind: a frame abandoned at its deadline, or still
// rendering when stop()'s grace ran out, that has not returned (or, with no
// device, a service thread stop() did not wait for: "between frames", "a
// renderer build").
struct StuckRender {
  std::string backend;
  std::string device;
  std::string stage;     // the stage it entered last ("unknown" when its backend named none)
  double seconds = 0.0;  // since its frame started
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
    // A frame rendering longer than this is abandoned (see above); 0 = no
    // deadline. Far above any legitimate frame (docs/service.md, "Frame
    // deadline"): it is there to catch a render that never returns.
    double frameDeadlineSeconds = 300.0;
    // stop() waits this long for the render threads (and a running build)
    // to end; those still inside a render then are left behind.
    double stopGraceSeconds = 1.5;
    // Lines for the server's log (a frame abandoned, a device healthy
    // again); empty = none. Called on service threads, never under a lock
    // the caller could take.
    std::function<void(const std::string&)> log;
    // The stages a build for a config will report, in order, with their
    // estimated work (render::planBuild): the sessions' BuildProgress then
    // carries the whole build's fraction and time left. Called on the
    // builder thread before the build; empty, or a plan that throws or is
    // empty: no plan (the stage fractions alone).
    std::function<render::BuildPlan(const SessionConfig&)> planner;
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
  // Every device rendered on so far, and the render threads left behind.
  std::vector<DeviceStatus> devices() const;
  std::vector<StuckRender> stuckRenders() const;

  // Cancels the renders in progress (they end at their next tile or batch
  // boundary, as cancelled) and abandons a running build, drops the queued
  // jobs and prepares (their callbacks destroyed uncalled), joins the
  // threads. A thread still inside a render (or a build) at `graceUntil`
  // is not waited for: it is left behind, detached (stuckRenders()), and
  // what it uses stays alive. Idempotent.
  void stop();  // graceUntil: now + Options::stopGraceSeconds
  void stop(std::chrono::steady_clock::time_point graceUntil);

 private:
  struct Impl;
  // Shared with the service's threads: one left behind keeps what it uses.
  std::shared_ptr<Impl> impl_;
};

}  // namespace haarcast::net
