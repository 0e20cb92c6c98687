// A renderer build's progress (build_progress.h): the tracker's throttle and
// estimate with a made-up clock, the stage names a client may see, the
// wire message, and the render service's fan-out to the sessions that wait
// for a build (render_service.h) with a builder that reports in steps.
#include "haarcast/net/build_progress.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <future>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "haarcast/net/messages.h"
#include "haarcast/net/render_service.h"
#include "stub_renderer.h"

namespace haarcast::net {
namespace {

using namespace std::chrono_literals;
using TrackerClock = BuildProgressTracker::Clock;

TEST(BuildProgressTracker, ANewStageAtOnceThenAtMostOneUpdatePerInterval) {
  const auto t0 = TrackerClock::time_point{} + 1h;
  BuildProgressTracker tracker(t0, 0.25);
  auto first = tracker.step("slices ball", 0, 32, t0);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->stageIndex, 0u);
  EXPECT_EQ(first->stageSecondsLeft, 0.0) << "no estimate before anything is done";
  // Within the interval: held back, however many steps.
  for (int i = 1; i < 20; ++i) EXPECT_FALSE(tracker.step("slices ball", static_cast<std::size_t>(i), 32, t0 + i * 10ms));
  // A new stage: at once, whatever the interval.
  auto visibility = tracker.step("visibility ball", 0, 1000, t0 + 210ms);
  ASSERT_TRUE(visibility);
  EXPECT_EQ(visibility->stageIndex, 1u);
  EXPECT_NEAR(visibility->elapsedSeconds, 0.21, 1e-9);
  EXPECT_FALSE(tracker.step("visibility ball", 100, 1000, t0 + 300ms)) << "0.09 s after the last update";
  // 250 of 1000 in 0.5 s since the stage began: 750 left at 500 a second.
  auto later = tracker.step("visibility ball", 250, 1000, t0 + 710ms);
  ASSERT_TRUE(later);
  EXPECT_NEAR(later->stageSecondsLeft, 1.5, 1e-9);
  EXPECT_DOUBLE_EQ(later->fraction(), 0.25);
  // Back to a stage seen before (an outer loop): throttled like any update,
  // and it keeps its index.
  EXPECT_FALSE(tracker.step("slices ball", 20, 32, t0 + 720ms));
  auto again = tracker.step("slices ball", 21, 32, t0 + 1s);
  ASSERT_TRUE(again);
  EXPECT_EQ(again->stageIndex, 0u);
}

TEST(BuildProgressTracker, FractionStaysInZeroToOne) {
  BuildProgressUpdate u;
  EXPECT_EQ(u.fraction(), 0.0) << "total unknown";
  u.done = 7;
  u.total = 5;
  EXPECT_EQ(u.fraction(), 1.0);
}

TEST(BuildProgressMessage, StageNamesShowNoServerPathAndStayPrintableUtf8) {
  EXPECT_EQ(publicStageName("visibility bunny"), "visibility bunny");
  EXPECT_EQ(publicStageName("slices /srv/haarcast/brdfs/steel.binary"), "slices steel.binary");
  EXPECT_EQ(publicStageName("slices C:\\data\\gold"), "slices gold");
  EXPECT_EQ(publicStageName("visibility \x1b[31mred\nline"), "visibility [31mred line");
  EXPECT_EQ(publicStageName("visibility caf\xc3\xa9"), "visibility caf\xc3\xa9");
  EXPECT_EQ(publicStageName("visibility bad\xff\xc3"), "visibility bad??");
  EXPECT_LE(publicStageName(std::string(500, 'x')).size(), kMaxStageBytes);
}

// The whole build against its plan (render::BuildPlan): the fraction weighs
// the stages by their planned work, counts a stage never reported (found in
// a cache) as done once a later one reports, holds through stages outside
// the plan and never goes back; the time left takes each kind's own rate.
TEST(BuildProgressTracker, TheBuildFractionFollowsThePlanAndTheEstimateEachKindsRate) {
  const auto t0 = TrackerClock::time_point{} + 1h;
  render::BuildPlan plan;
  plan.stages = {{"slices a", 1.0}, {"visibility a", 4.0}, {"slices b", 1.0}, {"visibility b", 4.0}};
  BuildProgressTracker tracker(t0, 0.25, plan);
  auto first = tracker.step("slices a", 0, 10, t0);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->buildFraction, 0.0);
  EXPECT_EQ(first->stages, (std::vector<std::string>{"slices a", "visibility a", "slices b", "visibility b"}));
  EXPECT_EQ(first->buildSecondsLeft, 0.0) << "no rate yet";
  // slices a: 1 unit of work in 2 s.
  auto slices = tracker.step("slices a", 10, 10, t0 + 2s);
  ASSERT_TRUE(slices);
  EXPECT_DOUBLE_EQ(slices->buildFraction, 0.1);
  // visibility a: half of its 4 units in the next 2 s (1 s a unit).
  ASSERT_TRUE(tracker.step("visibility a", 0, 100, t0 + 2s));
  auto half = tracker.step("visibility a", 50, 100, t0 + 4s);
  ASSERT_TRUE(half);
  EXPECT_DOUBLE_EQ(half->buildFraction, 0.3);
  // Left: visibility a's 2 units and visibility b's 4 at 1 s, slices b's 1 at 2 s.
  EXPECT_NEAR(half->buildSecondsLeft, 2.0 * 1.0 + 1.0 * 2.0 + 4.0 * 1.0, 1e-9);
  // slices b never reported (a cache hit): visibility b starts at 0.6.
  auto b = tracker.step("visibility b", 0, 100, t0 + 6s);
  ASSERT_TRUE(b);
  EXPECT_DOUBLE_EQ(b->buildFraction, 0.6);
  // Outside the plan, or an earlier stage again: the fraction holds.
  auto other = tracker.step("frame slots", 1, 2, t0 + 7s);
  ASSERT_TRUE(other);
  EXPECT_DOUBLE_EQ(other->buildFraction, 0.6);
  auto again = tracker.step("visibility a", 10, 100, t0 + 8s);
  ASSERT_TRUE(again);
  EXPECT_DOUBLE_EQ(again->buildFraction, 0.6);
  // Throttled reports still move it: the next one published says so.
  EXPECT_FALSE(tracker.step("visibility b", 50, 100, t0 + 8s + 10ms));
  auto later = tracker.step("visibility b", 50, 100, t0 + 9s);
  ASSERT_TRUE(later);
  EXPECT_DOUBLE_EQ(later->buildFraction, 0.8);
  // Without a plan: none of the build's fields.
  BuildProgressTracker bare(t0, 0.25);
  auto u = bare.step("slices a", 5, 10, t0);
  ASSERT_TRUE(u);
  EXPECT_EQ(u->buildFraction, 0.0);
  EXPECT_TRUE(u->stages.empty());
}

TEST(BuildProgressMessage, CarriesEveryField) {
  BuildProgressUpdate u{"visibility /home/op/bunny.ply", 2, 30, 120, 4.5, 2.25, 0.4,
                       {"slices /home/op/bunny.ply", "visibility /home/op/bunny.ply"}, 12.5};
  v1::ServerMessage m;
  ASSERT_TRUE(m.ParseFromString(buildProgressMessage(u)));
  ASSERT_TRUE(m.has_build_progress());
  const auto& b = m.build_progress();
  EXPECT_EQ(b.stage(), "visibility bunny.ply");
  EXPECT_EQ(b.stage_index(), 2u);
  EXPECT_EQ(b.done(), 30u);
  EXPECT_EQ(b.total(), 120u);
  EXPECT_DOUBLE_EQ(b.fraction(), 0.25);
  EXPECT_DOUBLE_EQ(b.elapsed_seconds(), 4.5);
  EXPECT_DOUBLE_EQ(b.estimated_stage_seconds_left(), 2.25);
  EXPECT_DOUBLE_EQ(b.build_fraction(), 0.4);
  ASSERT_EQ(b.stages_size(), 2);
  EXPECT_EQ(b.stages(0), "slices bunny.ply") << "the plan's names go out as the stage's: no server path";
  EXPECT_EQ(b.stages(1), "visibility bunny.ply");
  EXPECT_DOUBLE_EQ(b.estimated_build_seconds_left(), 12.5);
}

// ---------------------------------------------------------------- the service's fan-out

SessionConfig config(int level) {
  SessionConfig c;
  c.scene = "default";
  c.level = level;
  return c;
}

std::shared_ptr<PreparedRenderer> stub() {
  auto p = std::make_shared<PreparedRenderer>();
  p->renderer = std::make_unique<StubRenderer>();
  return p;
}

// What one prepare saw: its progress updates in order (and the thread of
// each), then its outcome.
struct Watcher {
  std::mutex mutex;
  std::vector<BuildProgressUpdate> updates;
  std::vector<std::thread::id> threads;
  std::vector<std::string> events;  // "progress" and "ready" / "failed", in order
  std::promise<PrepareStatus> outcome;

  RenderService::ProgressSink sink() {
    return [this](const BuildProgressUpdate& u) {
      std::lock_guard lock(mutex);
      updates.push_back(u);
      threads.push_back(std::this_thread::get_id());
      events.push_back("progress");
    };
  }
  RenderService::PrepareDone done() {
    return [this](PrepareOutcome o) {
      {
        std::lock_guard lock(mutex);
        events.push_back(o.status == PrepareStatus::Ready ? "ready" : "failed");
      }
      outcome.set_value(o.status);
    };
  }
  std::size_t count() {
    std::lock_guard lock(mutex);
    return updates.size();
  }
};

// Updates come stage by stage, and within a stage with more done each time.
void expectMonotone(const std::vector<BuildProgressUpdate>& updates) {
  for (std::size_t i = 1; i < updates.size(); ++i) {
    const auto &a = updates[i - 1], &b = updates[i];
    ASSERT_LE(a.stageIndex, b.stageIndex) << "update " << i;
    if (a.stageIndex == b.stageIndex) {
      EXPECT_LE(a.done, b.done) << "update " << i;
    }
    EXPECT_LE(a.elapsedSeconds, b.elapsedSeconds + 1e-9) << "update " << i;
    EXPECT_GE(b.fraction(), 0.0);
    EXPECT_LE(b.fraction(), 1.0);
  }
}

TEST(RenderServiceProgress, SessionsWaitingForOneBuildEachGetItsProgressThenReady) {
  Metrics metrics;
  std::atomic<bool> bJoined{false};
  constexpr std::size_t kSteps = 12;
  AbandonableRendererBuilder builder = [&](const SessionConfig&, const std::function<bool()>&,
                                           const render::RenderProgress& progress) {
    progress("slices ball", 0, kSteps);
    // b joins now, while the build runs: it gets the latest at once.
    while (!bJoined) std::this_thread::sleep_for(1ms);
    for (std::size_t i = 1; i <= kSteps; ++i) {
      std::this_thread::sleep_for(5ms);
      progress("slices ball", i, kSteps);
    }
    for (std::size_t i = 0; i <= kSteps; ++i) {
      progress("visibility ball", i, kSteps);
      std::this_thread::sleep_for(5ms);
    }
    return stub();
  };
  RenderService::Options options;
  options.progressIntervalSeconds = 0.02;
  Watcher a, b, cached;  // outlive the service, whose builder calls them
  RenderService service(builder, options, metrics);
  // Whatever ends the test, the builder is let go before the service joins it.
  struct Release {
    std::atomic<bool>& flag;
    ~Release() { flag = true; }
  } release{bJoined};
  service.prepare(config(4), "a", a.done(), a.sink());
  ASSERT_TRUE([&] {
    for (int i = 0; i < 5000 && a.count() == 0; ++i) std::this_thread::sleep_for(1ms);
    return a.count() == 1;
  }());
  service.prepare(config(4), "b", b.done(), b.sink());
  std::vector<BuildProgressUpdate> joined;  // what b had when prepare() returned
  {
    std::lock_guard lock(b.mutex);
    joined = b.updates;
    EXPECT_TRUE(joined.empty() || b.threads.front() == std::this_thread::get_id());
  }
  bJoined = true;
  ASSERT_EQ(joined.size(), 1u) << "a build already running: its latest progress at once, from within prepare()";
  EXPECT_EQ(joined.front().stage, "slices ball");
  for (Watcher* w : {&a, &b}) {
    auto f = w->outcome.get_future();
    ASSERT_EQ(f.wait_for(10s), std::future_status::ready);
    EXPECT_EQ(f.get(), PrepareStatus::Ready);
    std::lock_guard lock(w->mutex);
    expectMonotone(w->updates);
    EXPECT_EQ(w->events.back(), "ready");
    EXPECT_EQ(std::count(w->events.begin(), w->events.end(), "ready"), 1);
    EXPECT_GE(w->updates.size(), 3u) << "each stage's first, and steps within them";
    EXPECT_EQ(w->updates.back().stage, "visibility ball");
    EXPECT_EQ(w->updates.back().stageIndex, 1u);
  }
  // The renderer is cached now: ready at once, and nothing to report.
  service.prepare(config(4), "c", cached.done(), cached.sink());
  auto f = cached.outcome.get_future();
  ASSERT_EQ(f.wait_for(0s), std::future_status::ready);
  EXPECT_EQ(f.get(), PrepareStatus::Ready);
  EXPECT_EQ(cached.count(), 0u);
  EXPECT_EQ(cached.events, std::vector<std::string>{"ready"});
}

TEST(RenderServiceProgress, TheThrottleBoundsTheUpdatesOfABuildThatReportsOften) {
  Metrics metrics;
  std::atomic<std::size_t> reports{0};
  std::atomic<double> seconds{0.0};
  AbandonableRendererBuilder builder = [&](const SessionConfig&, const std::function<bool()>&,
                                           const render::RenderProgress& progress) {
    // One stage reported as often as the builder can for 0.4 s, then a
    // second stage likewise for 0.2 s.
    const auto t0 = std::chrono::steady_clock::now();
    std::size_t n = 0;
    for (const auto& [stage, until] : {std::pair{"visibility ball", 400ms}, std::pair{"visibility ring", 600ms}}) {
      for (std::size_t i = 0; std::chrono::steady_clock::now() - t0 < until; ++i, ++n) progress(stage, i, 1u << 30);
    }
    reports = n;
    seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return stub();
  };
  RenderService::Options options;
  options.progressIntervalSeconds = 0.1;
  Watcher w;
  RenderService service(builder, options, metrics);
  service.prepare(config(4), "a", w.done(), w.sink());
  auto f = w.outcome.get_future();
  ASSERT_EQ(f.wait_for(10s), std::future_status::ready);
  // One per 0.1 s, plus one at the second stage's start (the first stage's
  // start is the first of the 0.1 s ones).
  const auto bound = static_cast<std::size_t>(seconds.load() / options.progressIntervalSeconds) + 2;
  EXPECT_GT(reports.load(), 1000u) << "the builder reported often";
  EXPECT_LE(w.count(), bound) << reports.load() << " reports in " << seconds.load() << " s";
  EXPECT_GE(w.count(), 2u) << "each stage's start at least";
  std::lock_guard lock(w.mutex);
  expectMonotone(w.updates);
}

}  // namespace
}  // namespace haarcast::net
