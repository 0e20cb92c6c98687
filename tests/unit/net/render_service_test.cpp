#include "haarcast/net/render_service.h"
#include "haarcast/net/left_behind.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <future>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "settled_left_behind.h"

namespace haarcast::net {
namespace {

using namespace std::chrono_literals;

// A test double of the Renderer interface: a flat image after a short sleep,
// and a check that no two renders ever overlap (renderers are not
// thread-safe; the service must serialise them).
class FakeRenderer final : public render::Renderer {
 public:
  std::string backend() const override { return "fake"; }
  std::string deviceName() const override { return "fake device"; }
  const render::RenderOptions& options() const override { return options_; }
  std::size_t objectCount() const override { return 1; }
  render::Frame render(const render::FrameRequest& request) override {
    if (busy_.exchange(true)) overlapped.store(true);
    std::this_thread::sleep_for(2ms);
    render::Frame f;
    f.width = request.width;
    f.height = request.height;
    f.image = io::makeImage(request.width, request.height);
    f.rgba8.assign(static_cast<std::size_t>(request.width) * request.height * 4, 128);
    f.stages = {{"light", 0.001}};
    busy_.store(false);
    return f;
  }
  std::atomic<bool> overlapped{false};

 private:
  render::RenderOptions options_;
  std::atomic<bool> busy_{false};
};

std::optional<render::FrameRequest> request(int width, int height) {
  render::FrameRequest r;
  r.width = width;
  r.height = height;
  return r;
}

SessionConfig config(int level) {
  SessionConfig c;
  c.width = 8;
  c.height = 8;
  c.scene = "default";
  c.level = level;
  c.encoding = FrameEncoding::RawRgba8;
  return c;
}

// A renderer whose frames run a scripted body; it may render concurrently.
class ScriptedRenderer final : public render::Renderer {
 public:
  using Body = std::function<void(const render::FrameRequest&, render::Frame&)>;
  // slots: framesInFlight() (0: the interface's default for `concurrent`).
  ScriptedRenderer(bool concurrent, Body body, std::size_t slots = 0)
      : concurrent_(concurrent), body_(std::move(body)), slots_(slots) {}
  std::string backend() const override { return "scripted"; }
  std::string deviceName() const override { return "scripted device"; }
  const render::RenderOptions& options() const override { return options_; }
  std::size_t objectCount() const override { return 1; }
  bool concurrentRenders() const override { return concurrent_; }
  std::size_t framesInFlight() const override { return slots_ ? slots_ : render::Renderer::framesInFlight(); }
  render::Frame render(const render::FrameRequest& request) override {
    render::Frame f;
    f.width = request.width;
    f.height = request.height;
    body_(request, f);
    if (!f.cancelled) f.rgba8.assign(static_cast<std::size_t>(request.width) * request.height * 4, 7);
    return f;
  }

 private:
  render::RenderOptions options_;
  bool concurrent_;
  Body body_;
  std::size_t slots_;
};

std::shared_ptr<PreparedRenderer> scripted(bool concurrent, ScriptedRenderer::Body body, std::size_t slots = 0) {
  auto p = std::make_shared<PreparedRenderer>();
  p->renderer = std::make_unique<ScriptedRenderer>(concurrent, std::move(body), slots);
  return p;
}

// Waits (bounded) until `condition` holds; false if it never did.
bool waitUntil(const std::function<bool()>& condition, std::chrono::milliseconds limit = 5s) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (!condition()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(1ms);
  }
  return true;
}

// A job of `width`×`height` whose outcome lands in `log` ("done <error>",
// "frame" or "cancelled").
struct JobLog {
  std::mutex mutex;
  std::vector<std::string> events;
  void add(std::string e) {
    std::lock_guard lock(mutex);
    events.push_back(std::move(e));
  }
  std::vector<std::string> get() {
    std::lock_guard lock(mutex);
    return events;
  }
};
RenderJob job(std::shared_ptr<PreparedRenderer> renderer, int width, int height, JobLog& log, const std::string& name) {
  RenderJob j;
  j.renderer = std::move(renderer);
  j.encoding = FrameEncoding::RawRgba8;
  j.pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  j.take = [width, height] { return request(width, height); };
  j.done = [&log, name](std::optional<RenderedFrame> f, std::string e) { log.add(name + (f ? " frame" : " error " + e)); };
  j.onCancelled = [&log, name] { log.add(name + " cancelled"); };
  return j;
}

TEST(RenderService, SharesAndCachesRenderersLruBounded) {
  Metrics metrics;
  std::atomic<int> built{0};
  RenderService::Options options;
  options.maxRenderers = 1;
  RenderService service(
      [&](const SessionConfig&) {
        ++built;
        auto p = std::make_shared<PreparedRenderer>();
        p->renderer = std::make_unique<FakeRenderer>();
        return p;
      },
      options, metrics);
  auto prepareNow = [&](const SessionConfig& c) {
    std::promise<std::shared_ptr<PreparedRenderer>> promise;
    service.prepare(c, [&](std::shared_ptr<PreparedRenderer> r, std::string) { promise.set_value(r); });
    return promise.get_future().get();
  };
  const auto a = prepareNow(config(4));
  const auto b = prepareNow(config(4));
  EXPECT_EQ(a, b);  // one renderer for equal keys
  EXPECT_EQ(built.load(), 1);
  const auto c = prepareNow(config(3));
  EXPECT_NE(a, c);
  EXPECT_EQ(built.load(), 2);
  prepareNow(config(4));  // evicted by the bound of 1: built again
  EXPECT_EQ(built.load(), 3);
  EXPECT_EQ(metrics.renderersBuilt.load(), 3u);
}

TEST(RenderService, BuildFailureNamesTheError) {
  Metrics metrics;
  RenderService service([](const SessionConfig&) -> std::shared_ptr<PreparedRenderer> {
    throw std::runtime_error("no such probe: sky.exr");
  }, {}, metrics);
  std::promise<std::string> error;
  service.prepare(config(4), [&](std::shared_ptr<PreparedRenderer> r, std::string e) {
    EXPECT_EQ(r, nullptr);
    error.set_value(e);
  });
  EXPECT_EQ(error.get_future().get(), "no such probe: sky.exr");
}

// A build deaf to its abandonment (a library call) outlives stop()'s grace:
// it is left behind, named among the stuck, and counted in the process's
// threads left behind (net/left_behind.h) until it returns.
TEST(RenderService, ABuildPastTheStopGraceIsLeftBehindAndCountedUntilItReturns) {
  Metrics metrics;
  auto gate = std::make_shared<std::promise<void>>();
  std::shared_future<void> open = gate->get_future().share();
  std::atomic<bool> building{false};
  RenderService::Options options;
  options.stopGraceSeconds = 0.1;
  RenderService service([open, &building](const SessionConfig&) {
    building = true;
    open.wait();
    return std::make_shared<PreparedRenderer>();
  }, options, metrics);
  const std::size_t before = settledThreadsLeftBehind();
  service.prepare(config(4), [](std::shared_ptr<PreparedRenderer>, std::string) {});
  for (int i = 0; i < 2000 && !building; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ASSERT_TRUE(building.load());
  service.stop();
  EXPECT_EQ(threadsLeftBehind(), before + 1);
  const auto stuck = service.stuckRenders();
  ASSERT_EQ(stuck.size(), 1u);
  EXPECT_EQ(stuck[0].stage, "a renderer build");
  gate->set_value();
  for (int i = 0; i < 2000 && threadsLeftBehind() != before; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_EQ(threadsLeftBehind(), before);
  EXPECT_TRUE(service.stuckRenders().empty());
}

TEST(RenderService, RoundRobinIsFairAndRendersNeverOverlap) {
  Metrics metrics;
  auto fake = std::make_shared<PreparedRenderer>();
  auto* renderer = new FakeRenderer;
  fake->renderer.reset(renderer);
  RenderService::Options options;
  options.workers = 2;  // two workers on one renderer: still one render at a time
  RenderService service([&](const SessionConfig&) { return fake; }, options, metrics);

  constexpr int kSessions = 3;
  std::atomic<int> frames[kSessions] = {};
  std::atomic<bool> running{true};
  std::function<void(int)> submit = [&](int s) {
    RenderJob job;
    job.renderer = fake;
    job.encoding = FrameEncoding::RawRgba8;
    job.take = [] { return request(8, 8); };
    job.done = [&, s](std::optional<RenderedFrame> f, std::string e) {
      EXPECT_TRUE(f) << e;
      if (f) {
        EXPECT_EQ(f->encoded.size(), 8u * 8u * 4u);
      }
      ++frames[s];
      if (running.load()) submit(s);  // each session resubmits at once: the greediest client there is
    };
    service.submit(std::move(job));
  };
  for (int s = 0; s < kSessions; ++s) submit(s);
  std::this_thread::sleep_for(400ms);
  running.store(false);
  service.stop();
  const int a = frames[0].load(), b = frames[1].load(), c = frames[2].load();
  EXPECT_GT(a, 10);
  // Round robin: equal shares, up to the jobs caught in flight on two
  // workers and two encoders when the clock stops.
  EXPECT_LE(std::abs(a - b), 4) << a << " " << b << " " << c;
  EXPECT_LE(std::abs(a - c), 4) << a << " " << b << " " << c;
  EXPECT_FALSE(renderer->overlapped.load());
}

TEST(RenderService, AGoneSessionIsSkipped) {
  Metrics metrics;
  auto fake = std::make_shared<PreparedRenderer>();
  fake->renderer = std::make_unique<FakeRenderer>();
  RenderService service([&](const SessionConfig&) { return fake; }, {}, metrics);
  std::promise<void> second;
  std::atomic<bool> firstDone{false};
  std::atomic<bool> firstCancelled{false};
  RenderJob gone;
  gone.renderer = fake;
  gone.take = [] { return std::optional<render::FrameRequest>(); };
  gone.done = [&](std::optional<RenderedFrame>, std::string) { firstDone = true; };
  gone.onCancelled = [&] { firstCancelled = true; };
  service.submit(std::move(gone));
  RenderJob live;
  live.renderer = fake;
  live.take = [] { return request(4, 4); };
  live.done = [&](std::optional<RenderedFrame>, std::string) { second.set_value(); };
  service.submit(std::move(live));
  EXPECT_EQ(second.get_future().wait_for(5s), std::future_status::ready);
  EXPECT_FALSE(firstDone.load());
  EXPECT_TRUE(firstCancelled.load());
}

bool has(const std::vector<std::string>& events, const std::string& e) {
  return std::find(events.begin(), events.end(), e) != events.end();
}
std::ptrdiff_t indexOf(const std::vector<std::string>& events, const std::string& e) {
  return std::find(events.begin(), events.end(), e) - events.begin();
}

TEST(RenderService, FramesOfTwoSessionsRenderAtOnce) {
  Metrics metrics;
  std::mutex m;
  std::condition_variable cv;
  int inside = 0, most = 0;
  // Each frame waits (bounded) for another to be inside too: with one render
  // at a time, each times out alone.
  auto shared = scripted(true, [&](const render::FrameRequest&, render::Frame&) {
    std::unique_lock lock(m);
    most = std::max(most, ++inside);
    cv.notify_all();
    cv.wait_for(lock, 3s, [&] { return most >= 2; });
    --inside;
  });
  RenderService::Options options;
  options.workers = 2;
  RenderService service([&](const SessionConfig&) { return shared; }, options, metrics);
  JobLog log;
  service.submit(job(shared, 8, 8, log, "a"));  // two sessions, one shared renderer
  service.submit(job(shared, 8, 8, log, "b"));
  ASSERT_TRUE(waitUntil([&] { return log.get().size() == 2; }, 10s));
  std::lock_guard lock(m);
  EXPECT_EQ(most, 2);
}

// A renderer of two frames in flight (a Vulkan renderer on a GPU) gets two
// workers at once, never three: the others' jobs wait without a worker.
TEST(RenderService, ARendererOfTwoFramesInFlightRendersTwoAtOnceAndNoMore) {
  Metrics metrics;
  std::mutex m;
  std::condition_variable cv;
  int inside = 0, most = 0;
  bool open = false;
  auto slotted = scripted(
      true,
      [&](const render::FrameRequest&, render::Frame&) {
        std::unique_lock lock(m);
        most = std::max(most, ++inside);
        cv.notify_all();
        cv.wait_for(lock, 5s, [&] { return open; });
        --inside;
      },
      2);
  RenderService::Options options;
  options.workers = 4;
  RenderService service([&](const SessionConfig&) { return slotted; }, options, metrics);
  JobLog log;
  for (const char* name : {"a", "b", "c", "d"}) service.submit(job(slotted, 8, 8, log, name));
  ASSERT_TRUE(waitUntil([&] {
    std::lock_guard lock(m);
    return inside == 2;
  }));
  std::this_thread::sleep_for(50ms);  // a third would have started by now
  EXPECT_EQ(service.queued(), 2u);    // waiting without a worker
  {
    std::lock_guard lock(m);
    EXPECT_EQ(inside, 2);
    open = true;
  }
  cv.notify_all();
  ASSERT_TRUE(waitUntil([&] { return log.get().size() == 4; }, 10s));
  std::lock_guard lock(m);
  EXPECT_EQ(most, 2);
  for (const std::string& e : log.get()) EXPECT_NE(e.find("frame"), std::string::npos) << e;
}

TEST(RenderService, ThePixelBudgetHoldsAJobUntilAnotherFinishes) {
  Metrics metrics;
  JobLog log;
  std::atomic<bool> release{false};
  auto r = scripted(true, [&](const render::FrameRequest& q, render::Frame&) {
    log.add("start " + std::to_string(q.width));
    if (q.width == 10) waitUntil([&] { return release.load(); });
    log.add("end " + std::to_string(q.width));
  });
  RenderService::Options options;
  options.workers = 2;
  options.serverPixelBudget = 150;
  RenderService service([&](const SessionConfig&) { return r; }, options, metrics);
  service.submit(job(r, 10, 10, log, "big"));
  ASSERT_TRUE(waitUntil([&] { return has(log.get(), "start 10"); }));
  service.submit(job(r, 8, 8, log, "small"));  // 100 + 64 > 150: waits, though a worker is free
  EXPECT_TRUE(waitUntil([&] { return service.atPixelBudget(); }));
  EXPECT_EQ(service.pixelsInFlight(), 100u);
  std::this_thread::sleep_for(50ms);
  EXPECT_FALSE(has(log.get(), "start 8"));
  release = true;
  ASSERT_TRUE(waitUntil([&] { return has(log.get(), "small frame") && has(log.get(), "big frame"); }));
  const auto events = log.get();
  EXPECT_GT(indexOf(events, "start 8"), indexOf(events, "end 10"));
  // A job larger than the whole budget runs, alone.
  service.submit(job(r, 20, 20, log, "huge"));
  EXPECT_TRUE(waitUntil([&] { return has(log.get(), "huge frame"); }));
  EXPECT_TRUE(waitUntil([&] { return service.pixelsInFlight() == 0 && !service.atPixelBudget(); }));
}

TEST(RenderService, AFrameOverTheSessionLimitIsAnErrorNamingIt) {
  Metrics metrics;
  JobLog log;
  auto r = scripted(true, [&](const render::FrameRequest&, render::Frame&) { log.add("rendered"); });
  RenderService::Options options;
  options.maxSessionPixels = 64;
  RenderService service([&](const SessionConfig&) { return r; }, options, metrics);
  service.submit(job(r, 16, 16, log, "x"));
  ASSERT_TRUE(waitUntil([&] { return !log.get().empty(); }));
  EXPECT_EQ(log.get().front(),
            "x error a frame of 16×16 (256 pixels) is over the server's limit of 64 pixels per session "
            "(max-session-pixels)");
}

// A frame of `tiles` tiles of 1 ms that stops at a tile once cancelled.
ScriptedRenderer::Body tiledBody(int tiles, std::atomic<int>& done) {
  return [tiles, &done](const render::FrameRequest& q, render::Frame& f) {
    for (int t = 0; t < tiles; ++t) {
      if (q.cancelled && q.cancelled()) {
        f.cancelled = true;
        return;
      }
      std::this_thread::sleep_for(1ms);
      ++done;
    }
  };
}

TEST(RenderService, CancelledJobsEndWithoutAFrame) {
  Metrics metrics;
  JobLog log;
  constexpr int kTiles = 5000;
  std::atomic<int> tiles{0};
  auto r = scripted(false, tiledBody(kTiles, tiles));
  RenderService service([&](const SessionConfig&) { return r; }, {}, metrics);
  std::atomic<bool> stopA{false};
  RenderJob a = job(r, 8, 8, log, "a");
  a.cancelled = [&] { return stopA.load(); };
  service.submit(std::move(a));
  std::atomic<int> takenB{0};
  RenderJob b = job(r, 8, 8, log, "b");  // queued behind a on the same renderer, its session gone
  b.cancelled = [] { return true; };
  b.take = [&] { ++takenB; return request(8, 8); };
  service.submit(std::move(b));
  ASSERT_TRUE(waitUntil([&] { return tiles.load() >= 5; }));
  stopA = true;
  ASSERT_TRUE(waitUntil([&] { return log.get().size() == 2; }));
  EXPECT_TRUE(has(log.get(), "a cancelled"));
  EXPECT_TRUE(has(log.get(), "b cancelled"));
  EXPECT_LT(tiles.load(), kTiles);
  EXPECT_EQ(takenB.load(), 0);
}

TEST(RenderService, StopCancelsTheRunningFrame) {
  Metrics metrics;
  JobLog log;
  constexpr int kTiles = 5000;  // 5 s unless cancelled
  std::atomic<int> tiles{0};
  auto r = scripted(true, tiledBody(kTiles, tiles));
  RenderService service([&](const SessionConfig&) { return r; }, {}, metrics);
  service.submit(job(r, 8, 8, log, "a"));
  ASSERT_TRUE(waitUntil([&] { return tiles.load() >= 5; }));
  service.stop();
  EXPECT_LT(tiles.load(), kTiles);
  EXPECT_EQ(log.get(), std::vector<std::string>{"a cancelled"});
}

TEST(RenderService, ASettingsFloodKeepsOneBuildQueuedPerOwnerAndDelaysAnotherByOneBuild) {
  Metrics metrics;
  std::mutex m;
  std::vector<int> started;  // levels, in the order their builds started
  std::atomic<bool> release{false}, firstAbandoned{false};
  AbandonableRendererBuilder builder = [&](const SessionConfig& c, const std::function<bool()>& abandoned,
                                             const render::RenderProgress&) {
    {
      std::lock_guard lock(m);
      started.push_back(c.level);
    }
    if (c.level == 0) {
      waitUntil([&] { return release.load(); });
      firstAbandoned = abandoned();
      if (firstAbandoned) throw std::runtime_error("abandoned");
    }
    auto p = std::make_shared<PreparedRenderer>();
    p->renderer = std::make_unique<FakeRenderer>();
    return p;
  };
  RenderService service(builder, {}, metrics);
  auto startedCount = [&] {
    std::lock_guard lock(m);
    return started.size();
  };
  std::atomic<int> superseded{0};
  auto count = [&](PrepareOutcome o) { superseded += o.status == PrepareStatus::Superseded; };
  service.prepare(config(0), "a", count);
  ASSERT_TRUE(waitUntil([&] { return startedCount() == 1; }));
  std::promise<PrepareOutcome> aLast, bDone;
  constexpr int kFlood = 200;
  for (int i = 1; i <= kFlood; ++i) {
    if (i < kFlood) {
      service.prepare(config(i), "a", count);
    } else {
      service.prepare(config(i), "a", [&](PrepareOutcome o) { aLast.set_value(std::move(o)); });
    }
  }
  EXPECT_EQ(superseded.load(), kFlood);  // the running one's waiter and 199 queued ones
  EXPECT_EQ(service.queuedBuilds(), 1u);
  std::size_t startedWhenBServed = 0;
  service.prepare(config(1000), "b", [&](PrepareOutcome o) {
    startedWhenBServed = startedCount();
    bDone.set_value(std::move(o));
  });
  EXPECT_EQ(service.queuedBuilds(), 2u);
  release = true;
  auto b = bDone.get_future();
  ASSERT_EQ(b.wait_for(5s), std::future_status::ready);
  EXPECT_EQ(b.get().status, PrepareStatus::Ready);
  EXPECT_TRUE(firstAbandoned.load());  // nobody waited for it any more
  // Started before b was served: the abandoned build and b's own. a was
  // served by the first build, so b's first goes ahead of a's latest: the
  // flood delays b by no whole build.
  EXPECT_EQ(startedWhenBServed, 2u);
  auto a = aLast.get_future();
  ASSERT_EQ(a.wait_for(5s), std::future_status::ready);
  const PrepareOutcome last = a.get();
  EXPECT_EQ(last.status, PrepareStatus::Ready);
  EXPECT_EQ(last.renderer->key, config(kFlood).rendererKey());
}

TEST(RenderService, TheBuildQueueIsBoundedAcrossTheServer) {
  Metrics metrics;
  std::atomic<bool> release{false};
  RenderService::Options options;
  options.maxQueuedBuilds = 2;
  RenderService service(
      [&](const SessionConfig& c) {
        if (c.level == 0) waitUntil([&] { return release.load(); });
        auto p = std::make_shared<PreparedRenderer>();
        p->renderer = std::make_unique<FakeRenderer>();
        return p;
      },
      options, metrics);
  JobLog log;
  auto record = [&](const std::string& who) {
    return [&log, who](PrepareOutcome o) {
      const char* status[] = {" ready", " failed", " refused ", " superseded"};
      log.add(who + status[static_cast<int>(o.status)] + o.error);
    };
  };
  service.prepare(config(0), "running", record("running"));
  ASSERT_TRUE(waitUntil([&] { return service.queuedBuilds() == 0; }));  // taken by the builder
  service.prepare(config(1), "o1", record("o1"));
  service.prepare(config(2), "o2", record("o2"));
  service.prepare(config(1), "o4", record("o4"));  // joins o1's build: no new one
  service.prepare(config(1), "o1", record("o1 again"));  // the same build: o1's first callback superseded
  EXPECT_EQ(service.queuedBuilds(), 2u);
  service.prepare(config(3), "o3", record("o3"));
  EXPECT_EQ(log.get(), (std::vector<std::string>{"o1 superseded", "o3 refused the server has 2 renderer builds queued, "
                                                 "its limit (max-queued-builds); try again later"}));
  service.withdraw("o2");  // its session closed: its build is dropped, unanswered
  EXPECT_EQ(service.queuedBuilds(), 1u);
  service.prepare(config(3), "o3", record("o3"));
  release = true;
  ASSERT_TRUE(waitUntil([&] { return log.get().size() == 6; }));
  for (const char* ready : {"running ready", "o1 again ready", "o4 ready", "o3 ready"}) EXPECT_TRUE(has(log.get(), ready)) << ready;
  EXPECT_FALSE(has(log.get(), "o2 ready"));
}

}  // namespace
}  // namespace haarcast::net
