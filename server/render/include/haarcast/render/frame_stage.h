// Where a frame is while it renders: the stage a backend has entered (the
// names of renderer.h's table), for a watchdog on another thread — the
// render service's frame deadline names the stage a stuck frame was in
// (docs/service.md, "Frame deadline").
//
// A backend calls enterFrameStage(request, "gbuffer") as it enters each
// stage: one relaxed atomic store of a string literal's address when a
// watcher gave the request a StageMark, nothing else otherwise. No lock, no
// allocation, safe from any of the render's threads.
#pragma once

#include <atomic>

namespace haarcast::render {

class StageMark {
 public:
  // `stage` must have static storage (a string literal): a watcher may read
  // it long after the frame has moved on, or never returned.
  void enter(const char* stage) { stage_.store(stage, std::memory_order_relaxed); }
  // The last stage entered; nullptr before the first.
  const char* current() const { return stage_.load(std::memory_order_relaxed); }

 private:
  std::atomic<const char*> stage_{nullptr};
};

struct FrameRequest;

// Publishes `stage` to the request's StageMark, if it has one.
//
// Test-only fault injection: when the environment variable
// HAARCAST_TEST_STALL_STAGE names `stage` (read once per process), a frame
// that has a StageMark blocks here for ever, deaf to cancellation, as a
// render stuck inside a library call would. Only watched frames (the
// server's) stall; `haarcast render` and bench-frame never do. The
// end-to-end test of the frame deadline and of SIGTERM uses it
// (tests/e2e/stuck_render.sh); it has no other use.
void enterFrameStage(const FrameRequest& request, const char* stage);

}  // namespace haarcast::render
