// A renderer build's progress as its sessions see it (ServerMessage
// BuildProgress): what the builder reports through render::RenderProgress
// (stage, done, total), turned into updates with the time elapsed and an
// estimate of the time left, at a bounded rate.
//
//   builder thread   progress("visibility bunny", 4200, 35947)
//        │           BuildProgressTracker::step(…, now) → an update, or none (throttled)
//        ▼
//   RenderService    the update to every session waiting for the build
//        │           (render_service.h), and kept for one that joins later
//        ▼
//   RenderSession    ServerMessage.build_progress (messages.h)
//
// Pure: the clock is passed in, so the throttle and the estimate are tested
// without threads or sleeps.
#pragma once

#include <chrono>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace haarcast::net {

// One update: what BuildProgress carries, before it is put on the wire.
struct BuildProgressUpdate {
  std::string stage;              // as the builder names it: "slices bunny", "visibility bunny" …
  std::size_t stageIndex = 0;     // 0 for the build's first stage, in the order the stages first appeared
  std::size_t done = 0, total = 0;
  double elapsedSeconds = 0.0;    // since the build started
  double stageSecondsLeft = 0.0;  // an estimate from the stage's rate so far; 0 = none yet

  // done / total in [0, 1]; 0 when the total is unknown (0).
  double fraction() const;
};

// The throttle and the estimate of one build; used by the builder thread only.
class BuildProgressTracker {
 public:
  using Clock = std::chrono::steady_clock;

  // At most one update per `minIntervalSeconds`, besides the one at each new stage.
  BuildProgressTracker(Clock::time_point started, double minIntervalSeconds);

  // The builder reported `done` of `total` items of `stage` at `now`. An
  // update to publish, or nullopt when the last one was too recent. A stage
  // not seen before in this build is published at once, whatever the
  // interval: a client learns each step when it begins, and the number of
  // stages is small (a few per object). A stage seen before (an outer loop
  // whose items run inner stages) is throttled like any update, so stages
  // that alternate cannot flood the sessions.
  std::optional<BuildProgressUpdate> step(const std::string& stage, std::size_t done, std::size_t total,
                                          Clock::time_point now);

 private:
  struct Stage {
    std::string name;
    Clock::time_point start;  // first reported
    std::size_t startDone = 0;  // done when first reported: the rate counts from there
  };

  Clock::time_point started_;
  Clock::duration minInterval_;
  std::vector<Stage> stages_;  // in the order they appeared; the index is stageIndex
  std::optional<Clock::time_point> lastPublished_;
};

// The stage name a client may see: printable ASCII and UTF-8 kept, control
// characters dropped, a word that looks like a path ('/' or '\') cut to its
// last part, at most kMaxStageBytes bytes (cut on a UTF-8 boundary). The
// builder names stages after the scene's objects, which the operator's scene
// files name; no server path reaches a client even if one ever does.
inline constexpr std::size_t kMaxStageBytes = 80;
std::string publicStageName(std::string_view stage);

}  // namespace haarcast::net
