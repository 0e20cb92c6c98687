// A renderer build's progress as its sessions see it (ServerMessage
// BuildProgress): what the builder reports through render::RenderProgress
// (stage, done, total), turned into updates with the time elapsed, the
// whole build's fraction against its plan (render::BuildPlan: the stages
// in order, each with its estimated work) and estimates of the time left,
// at a bounded rate.
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

#include "haarcast/render/build_plan.h"

namespace haarcast::net {

// One update: what BuildProgress carries, before it is put on the wire.
struct BuildProgressUpdate {
  std::string stage;              // as the builder names it: "slices bunny", "visibility bunny" …
  std::size_t stageIndex = 0;     // 0 for the build's first stage, in the order the stages first appeared
  std::size_t done = 0, total = 0;
  double elapsedSeconds = 0.0;    // since the build started
  double stageSecondsLeft = 0.0;  // an estimate from the stage's rate so far; 0 = none yet
  // The whole build (BuildPlan): its fraction, never decreasing; the planned
  // stages in order; the seconds left at its rate so far (0 = none yet).
  // All empty or 0 without a plan.
  double buildFraction = 0.0;
  std::vector<std::string> stages;
  double buildSecondsLeft = 0.0;

  // done / total in [0, 1]; 0 when the total is unknown (0).
  double fraction() const;
};

// The throttle and the estimates of one build; used by the builder thread only.
//
// The build's fraction: the planned stages before the one reported count
// whole (those never reported were skipped, e.g. found in a cache), the
// reported one by its own fraction, each weighted by its planned work; it
// never goes back, and a stage outside the plan leaves it where it was.
//
// The build's time left: the planned work left, each stage's at the rate
// measured on the stages of its kind ("slices", "visibility" …: the first
// word) reported so far, or at the build's rate over all of them for a kind
// not seen yet (seconds per planned work unit). Only reported stages count
// toward a rate: a skipped one took no time. None before the reported
// stages have done a fiftieth of the planned work in half a second or more.
class BuildProgressTracker {
 public:
  using Clock = std::chrono::steady_clock;

  // At most one update per `minIntervalSeconds`, besides the one at each new
  // stage. An empty plan: no build fraction or build estimate.
  BuildProgressTracker(Clock::time_point started, double minIntervalSeconds, render::BuildPlan plan = {});

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
    std::optional<std::size_t> planned;  // its index in the plan
    double fraction = 0.0;      // the largest reported
  };

  double buildSecondsLeft(std::size_t current, Clock::time_point now) const;

  Clock::time_point started_;
  Clock::duration minInterval_;
  render::BuildPlan plan_;
  double planWork_ = 0.0;
  double buildFraction_ = 0.0;
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
