// A long frame's progress as its client sees it (ServerMessage
// FrameProgress): the stage its render is in (render::StageMark, which the
// backend moves on), turned into one fraction of the whole frame that never
// goes back, an estimate of the time left, and a rule for when to say so.
//
//   render thread   enterFrameStage(request, "fused", rows); a tick per row
//        │          (render/frame_stage.h)
//        ▼
//   session strand  FrameProgressTracker::poll(mark, now) on each tick
//        │          (render_session.cpp) → an update, or none
//        ▼
//   client          ServerMessage.frame_progress (messages.h)
//
// Pure: the clock is passed in, so the rule and the fractions are tested
// without threads or sleeps.
#pragma once

#include <chrono>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "haarcast/render/frame_stage.h"
#include "haarcast/render/renderer.h"

namespace haarcast::net {

// A frame says nothing for this long: most frames end before it, and a
// message per frame would cost more than it tells.
inline constexpr double kFrameProgressAfterSeconds = 0.5;
// Then at most this often (a progress bar needs no more).
inline constexpr double kFrameProgressIntervalSeconds = 0.25;
// The stage before a render thread has taken the frame (the server's other
// frames, or its pixel budget, come first).
inline constexpr const char* kQueuedStage = "queued";

struct FrameProgressUpdate {
  std::string stage;            // renderer.h's stage names, or kQueuedStage
  double stageFraction = 0.0;   // of the stage's tiles started; 0 where the backend cannot say
  double fraction = 0.0;        // of the whole frame, never less than the last update's
  double elapsedSeconds = 0.0;  // since the frame was ordered
  double secondsLeft = 0.0;     // an estimate; 0 = none yet
};

// The frame's fraction when it is `stageFraction` into `stage`: the stages
// weighted by their times in `last` (its renderer's last frame, in pipeline
// order), or, before any frame, by default shares. A stage's weight runs
// from where it starts in that order; a stage `last` does not name gives
// nullopt (the caller keeps the fraction it had).
std::optional<double> frameFraction(std::string_view stage, double stageFraction,
                                    const std::vector<render::StageTime>& last);

// The weights before a renderer's first frame: rough shares of a frame's
// time per stage for `method`, in pipeline order (the CPU backend at 256²;
// a first frame's light, resolved afresh, takes a larger share).
std::vector<render::StageTime> defaultStageShares(RotationMethod method);

// One frame's progress, from its order to its end; on the session's strand.
class FrameProgressTracker {
 public:
  using Clock = std::chrono::steady_clock;

  // `last`: the renderer's last frame (PreparedRenderer::lastFrame), its
  // stage times scaled by pixels / lastPixels for the estimate; empty (no
  // frame yet): `method`'s defaultStageShares, and no estimate until the
  // frame is a tenth done.
  FrameProgressTracker(Clock::time_point ordered, RotationMethod method, std::vector<render::StageTime> last,
                       std::size_t lastPixels, std::size_t pixels);

  // Called on every tick (it notes when the frame leaves the queue). An
  // update to send now, or nullopt: before kFrameProgressAfterSeconds,
  // or within kFrameProgressIntervalSeconds of the last one. Sent even when
  // the stage has not moved (a GPU submission says nothing until it ends):
  // the client knows the server is still at it.
  std::optional<FrameProgressUpdate> poll(const render::StageMark& mark, Clock::time_point now);

 private:
  Clock::time_point ordered_;
  std::vector<render::StageTime> last_;
  double expectedSeconds_ = 0.0;  // the last frame's render time scaled to this one's pixels; 0 = unknown
  Clock::time_point queuedUntil_;  // the last poll that saw it queued (its order, if none)
  std::optional<Clock::time_point> lastSent_;
  double fraction_ = 0.0;
};

}  // namespace haarcast::net
