// Where a frame is while it renders: the stage a backend has entered (the
// names of renderer.h's table) and how far into it, for watchers on other
// threads — the render service's frame deadline names the stage a stuck
// frame was in (docs/service.md, "Frame deadline"), and a session shows a
// long frame's progress to its client (FrameProgress).
//
// A backend calls enterFrameStage(request, "gbuffer", tiles) as it enters
// each stage, saying how many tiles (CPU: rows of its passes) the stage
// has when it knows, and tickFrameStage(request) as each tile starts:
// relaxed atomic stores when a watcher gave the request a StageMark,
// nothing else otherwise. No lock, no allocation, safe from any of the
// render's threads.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>

namespace haarcast::render {

class StageMark {
 public:
  // `stage` must have static storage (a string literal): a watcher may read
  // it long after the frame has moved on, or never returned.
  // `tiles`: how many ticks the stage will have; 0 = not known.
  void enter(const char* stage, std::size_t tiles = 0) {
    // The ticks are reset before the stage is published: a watcher that
    // sees the new stage never reads the old stage's count against it.
    ticks_.store(0, std::memory_order_relaxed);
    tiles_.store(tiles, std::memory_order_relaxed);
    stage_.store(stage, std::memory_order_release);
  }
  void tick() { ticks_.fetch_add(1, std::memory_order_relaxed); }
  // The last stage entered; nullptr before the first.
  const char* current() const { return stage_.load(std::memory_order_acquire); }
  // The share of the current stage's tiles started, in [0, 1]; 0 when the
  // stage did not say how many it has.
  double fraction() const {
    const std::size_t tiles = tiles_.load(std::memory_order_relaxed);
    if (tiles == 0) return 0.0;
    return std::min(1.0, static_cast<double>(ticks_.load(std::memory_order_relaxed)) / static_cast<double>(tiles));
  }

 private:
  std::atomic<const char*> stage_{nullptr};
  std::atomic<std::size_t> tiles_{0};
  std::atomic<std::size_t> ticks_{0};
};

struct FrameRequest;

// Publishes `stage` (with its tile count, 0 = unknown) to the request's
// StageMark, if it has one.
//
// Test-only fault injection: when the environment variable
// HAARCAST_TEST_STALL_STAGE names `stage` (read once per process), a frame
// that has a StageMark blocks here for ever, deaf to cancellation, as a
// render stuck inside a library call would. Only watched frames (the
// server's) stall; `haarcast render` and bench-frame never do. The
// end-to-end test of the frame deadline and of SIGTERM uses it
// (tests/e2e/stuck_render.sh); it has no other use.
void enterFrameStage(const FrameRequest& request, const char* stage, std::size_t tiles = 0);
// One tile of the current stage started.
void tickFrameStage(const FrameRequest& request);

}  // namespace haarcast::render
