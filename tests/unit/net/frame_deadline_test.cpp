// A render that never returns (frame_workers.h): the frame deadline abandons
// it, naming its stage, freeing its pixels and marking its device unhealthy;
// jobs for that device fail at once, other devices keep rendering, and
// stop() does not wait for the stuck thread. The renders here block on a
// condition variable inside a named stage, as a library call that hangs.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "haarcast/net/render_service.h"
#include "haarcast/net/left_behind.h"
#include "settled_left_behind.h"
#include "haarcast/render/frame_stage.h"

namespace haarcast::net {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Opened once (or never): what a stuck render waits for. Shared with the
// render, which may outlive the test's stack (its thread is left behind).
struct Gate {
  std::mutex mutex;
  std::condition_variable cv;
  bool open = false;
  void wait() {
    std::unique_lock lock(mutex);
    cv.wait(lock, [this] { return open; });
  }
  void release() {
    {
      std::lock_guard lock(mutex);
      open = true;
    }
    cv.notify_all();
  }
};

// A renderer on a named device: its frames enter `stage` and, with a gate,
// block there until it opens (deaf to cancellation, as a hung driver call);
// without one they take `frameTime`.
class DeviceRenderer final : public render::Renderer {
 public:
  DeviceRenderer(std::string backend, std::string device, bool concurrent, const char* stage,
                 std::shared_ptr<Gate> gate, std::chrono::microseconds frameTime = 2ms)
      : backend_(std::move(backend)),
        device_(std::move(device)),
        concurrent_(concurrent),
        stage_(stage),
        gate_(std::move(gate)),
        frameTime_(frameTime) {}
  std::string backend() const override { return backend_; }
  std::string deviceName() const override { return device_; }
  const render::RenderOptions& options() const override { return options_; }
  std::size_t objectCount() const override { return 1; }
  bool concurrentRenders() const override { return concurrent_; }
  render::Frame render(const render::FrameRequest& request) override {
    render::enterFrameStage(request, "light");
    render::enterFrameStage(request, stage_);
    if (gate_) {
      gate_->wait();
    } else {
      std::this_thread::sleep_for(frameTime_);
    }
    render::Frame f;
    f.width = request.width;
    f.height = request.height;
    f.rgba8.assign(static_cast<std::size_t>(request.width) * static_cast<std::size_t>(request.height) * 4, 9);
    return f;
  }

 private:
  render::RenderOptions options_;
  std::string backend_, device_;
  bool concurrent_;
  const char* stage_;
  std::shared_ptr<Gate> gate_;
  std::chrono::microseconds frameTime_;
};

std::shared_ptr<PreparedRenderer> prepared(std::unique_ptr<render::Renderer> r) {
  auto p = std::make_shared<PreparedRenderer>();
  p->renderer = std::move(r);
  return p;
}
std::shared_ptr<PreparedRenderer> stuckOn(const std::string& device, const char* stage, std::shared_ptr<Gate> gate) {
  return prepared(std::make_unique<DeviceRenderer>("vulkan", device, false, stage, std::move(gate)));
}
std::shared_ptr<PreparedRenderer> cpu(std::chrono::microseconds frameTime = 2ms) {
  return prepared(std::make_unique<DeviceRenderer>("cpu", "cpu0", true, "fused", nullptr, frameTime));
}

bool waitUntil(const std::function<bool()>& condition, std::chrono::milliseconds limit = 5s) {
  const auto end = Clock::now() + limit;
  while (!condition()) {
    if (Clock::now() > end) return false;
    std::this_thread::sleep_for(1ms);
  }
  return true;
}

// Outcomes by job name: "frame", "error <message>" or "cancelled".
struct Outcomes {
  std::mutex mutex;
  std::vector<std::pair<std::string, std::string>> events;
  void add(const std::string& name, std::string what) {
    std::lock_guard lock(mutex);
    events.emplace_back(name, std::move(what));
  }
  std::vector<std::string> of(const std::string& name) {
    std::lock_guard lock(mutex);
    std::vector<std::string> out;
    for (const auto& [n, what] : events) {
      if (n == name) out.push_back(what);
    }
    return out;
  }
};

RenderJob job(std::shared_ptr<PreparedRenderer> renderer, Outcomes& outcomes, const std::string& name) {
  RenderJob j;
  j.renderer = std::move(renderer);
  j.encoding = FrameEncoding::RawRgba8;
  j.pixels = 64;
  j.take = [] {
    render::FrameRequest r;
    r.width = 8;
    r.height = 8;
    return std::optional<render::FrameRequest>(r);
  };
  j.done = [&outcomes, name](std::optional<RenderedFrame> f, std::string e) {
    outcomes.add(name, f ? "frame" : "error " + e);
  };
  j.onCancelled = [&outcomes, name] { outcomes.add(name, "cancelled"); };
  return j;
}

RenderService::Options withDeadline(double seconds) {
  RenderService::Options o;
  o.frameDeadlineSeconds = seconds;
  return o;
}

std::shared_ptr<PreparedRenderer> noBuilds(const SessionConfig&) { throw std::runtime_error("no builds here"); }

TEST(FrameDeadline, AStuckFrameIsAbandonedNamingItsStageAndItsDeviceFailsFast) {
  Metrics metrics;
  std::mutex logMutex;
  std::vector<std::string> logLines;
  RenderService::Options options = withDeadline(0.3);
  options.log = [&](const std::string& line) {
    std::lock_guard lock(logMutex);
    logLines.push_back(line);
  };
  RenderService service(noBuilds, options, metrics);
  Outcomes outcomes;
  const auto gate = std::make_shared<Gate>();  // never opened
  const auto t0 = Clock::now();
  service.submit(job(stuckOn("gpu0", "shadow-rays", gate), outcomes, "stuck"));
  ASSERT_TRUE(waitUntil([&] { return service.pixelsInFlight() == 64; }));
  ASSERT_TRUE(waitUntil([&] { return !outcomes.of("stuck").empty(); }));
  const double after = secondsSince(t0);
  EXPECT_GE(after, 0.3);
  EXPECT_LT(after, 1.5);
  EXPECT_EQ(outcomes.of("stuck"),
            std::vector<std::string>{"error frame abandoned after 0.3 s in stage shadow-rays on device gpu0 "
                                     "(frame-deadline); the device is marked unhealthy"});
  EXPECT_EQ(service.pixelsInFlight(), 0u);  // its share of the budget is back
  EXPECT_EQ(metrics.framesAbandoned.load(), 1u);
  const auto devices = service.devices();
  ASSERT_EQ(devices.size(), 1u);
  EXPECT_EQ(devices[0].device, "gpu0");
  EXPECT_FALSE(devices[0].healthy);
  EXPECT_EQ(devices[0].reason, "a frame abandoned after 0.3 s in stage shadow-rays");
  const auto stuck = service.stuckRenders();
  ASSERT_EQ(stuck.size(), 1u);
  EXPECT_EQ(stuck[0].stage, "shadow-rays");
  EXPECT_EQ(stuck[0].device, "gpu0");
  {
    std::lock_guard lock(logMutex);
    ASSERT_FALSE(logLines.empty());
    EXPECT_NE(logLines.front().find("frame abandoned after 0.3 s in stage shadow-rays on device gpu0"), std::string::npos)
        << logLines.front();
  }

  // Another renderer on the same device: its job fails at once, naming the
  // device and why, without rendering.
  const auto t1 = Clock::now();
  service.submit(job(stuckOn("gpu0", "gbuffer", gate), outcomes, "later"));
  ASSERT_TRUE(waitUntil([&] { return !outcomes.of("later").empty(); }));
  EXPECT_LT(secondsSince(t1), 0.1);
  EXPECT_EQ(outcomes.of("later"),
            std::vector<std::string>{"error device gpu0 (vulkan) is unhealthy: a frame abandoned after 0.3 s in stage "
                                     "shadow-rays and has not returned; its frames fail until it does or the server "
                                     "restarts"});
  // Another device renders on.
  service.submit(job(cpu(), outcomes, "cpu"));
  ASSERT_TRUE(waitUntil([&] { return !outcomes.of("cpu").empty(); }));
  EXPECT_EQ(outcomes.of("cpu"), std::vector<std::string>{"frame"});

  const auto t2 = Clock::now();
  service.stop();  // the stuck thread is not joined
  EXPECT_LT(secondsSince(t2), 0.5);  // it was abandoned already: nothing to wait for
  EXPECT_EQ(service.stuckRenders().size(), 1u);
}

TEST(FrameDeadline, StopDoesNotWaitForAStuckRenderPastItsGrace) {
  Metrics metrics;
  RenderService service(noBuilds, withDeadline(0.0), metrics);  // no deadline: only the grace
  Outcomes outcomes;
  service.submit(job(stuckOn("gpu0", "gbuffer", std::make_shared<Gate>()), outcomes, "stuck"));
  ASSERT_TRUE(waitUntil([&] { return service.pixelsInFlight() == 64; }));
  std::this_thread::sleep_for(50ms);
  const auto t0 = Clock::now();
  service.stop();  // the default grace: 1.5 s
  const double took = secondsSince(t0);
  EXPECT_GE(took, 1.4);
  EXPECT_LT(took, 2.0);
  const auto stuck = service.stuckRenders();
  ASSERT_EQ(stuck.size(), 1u);
  EXPECT_EQ(stuck[0].stage, "gbuffer");
  EXPECT_EQ(stuck[0].device, "gpu0");
  EXPECT_GE(stuck[0].seconds, 1.4);
  EXPECT_TRUE(outcomes.of("stuck").empty());  // stop() answers nobody
}

// Frames per second of `sessions` CPU sessions, each resubmitting at once,
// over `window`.
double cpuRate(RenderService& service, const std::shared_ptr<PreparedRenderer>& renderer, int sessions,
               std::chrono::milliseconds window) {
  std::atomic<int> frames{0};
  std::atomic<bool> counting{true};
  std::atomic<int> inFlight{0};
  std::function<void()> submit = [&] {
    RenderJob j;
    j.renderer = renderer;
    j.encoding = FrameEncoding::RawRgba8;
    j.take = [] {
      render::FrameRequest r;
      r.width = r.height = 4;
      return std::optional<render::FrameRequest>(r);
    };
    ++inFlight;
    j.done = [&](std::optional<RenderedFrame> f, std::string) {
      if (f && counting) ++frames;
      if (counting) submit();
      --inFlight;
    };
    j.onCancelled = [&] { --inFlight; };
    service.submit(std::move(j));
  };
  for (int s = 0; s < sessions; ++s) submit();
  std::this_thread::sleep_for(window);
  const double rate = frames.load() / std::chrono::duration<double>(window).count();
  counting = false;
  waitUntil([&] { return inFlight.load() == 0; });
  return rate;
}

TEST(FrameDeadline, AStuckDeviceLeavesOtherDevicesAtLeastHalfTheirFrameRate) {
  // Four workers, four CPU sessions; then four sessions of four Vulkan
  // renderers on one device whose frames hang. They take turns on the
  // device's one busy flag: one worker is stuck, the other three keep
  // serving the CPU. (Per renderer, all four workers would hang: 0 fps.)
  // No deadline here, so nothing is replaced during the measurement.
  Metrics metrics;
  RenderService::Options options = withDeadline(0.0);
  options.workers = 4;
  options.stopGraceSeconds = 0.1;
  RenderService service(noBuilds, options, metrics);
  const auto renderer = cpu(2ms);
  const double alone = cpuRate(service, renderer, 4, 400ms);
  Outcomes outcomes;
  const auto gate = std::make_shared<Gate>();
  for (int i = 0; i < 4; ++i) service.submit(job(stuckOn("gpu0", "shadow-rays", gate), outcomes, "stuck"));
  ASSERT_TRUE(waitUntil([&] { return service.pixelsInFlight() >= 64; }));
  const double withStuck = cpuRate(service, renderer, 4, 400ms);
  std::printf("CPU sessions: %.0f frames/s alone, %.0f with a stuck device (%.0f %%)\n", alone, withStuck,
              100.0 * withStuck / alone);
  EXPECT_GT(alone, 100.0);
  EXPECT_GE(withStuck, 0.5 * alone);
  EXPECT_EQ(service.queued(), 3u);  // the device's other jobs wait without a worker
  service.stop();
  gate->release();  // the left-behind render returns, and its thread ends quietly
}

TEST(FrameDeadline, AnAbandonedFrameThatReturnsIsDroppedAndItsDeviceRecovers) {
  Metrics metrics;
  std::mutex logMutex;
  std::vector<std::string> logLines;
  RenderService::Options options = withDeadline(0.2);
  options.log = [&](const std::string& line) {
    std::lock_guard lock(logMutex);
    logLines.push_back(line);
  };
  RenderService service(noBuilds, options, metrics);
  Outcomes outcomes;
  const auto gate = std::make_shared<Gate>();
  const auto renderer = stuckOn("gpu0", "tonemap", gate);
  // The process's count of threads left behind (net/left_behind.h): one
  // more while the abandoned render is out, back once it has returned.
  const std::size_t leftBefore = settledThreadsLeftBehind();
  service.submit(job(renderer, outcomes, "stuck"));
  ASSERT_TRUE(waitUntil([&] { return !outcomes.of("stuck").empty(); }));
  ASSERT_FALSE(service.devices().at(0).healthy);
  EXPECT_EQ(threadsLeftBehind(), leftBefore + 1);
  gate->release();
  ASSERT_TRUE(waitUntil([&] { return service.devices().at(0).healthy && service.stuckRenders().empty(); }));
  EXPECT_EQ(threadsLeftBehind(), leftBefore);
  std::this_thread::sleep_for(50ms);
  EXPECT_EQ(outcomes.of("stuck").size(), 1u);  // the late frame answered nobody: the error stays the only outcome
  {
    std::lock_guard lock(logMutex);
    ASSERT_EQ(logLines.size(), 2u);
    EXPECT_NE(logLines[1].find("device gpu0 (vulkan) is healthy again"), std::string::npos) << logLines[1];
  }
  service.submit(job(renderer, outcomes, "again"));  // the gate is open now: it renders
  ASSERT_TRUE(waitUntil([&] { return !outcomes.of("again").empty(); }));
  EXPECT_EQ(outcomes.of("again"), std::vector<std::string>{"frame"});
  // (The frame is answered from an encode thread, maybe before its worker
  // has given its pixels back.)
  EXPECT_TRUE(waitUntil([&] { return service.pixelsInFlight() == 0; }));
}

TEST(FrameDeadline, RenderersOfOneDeviceTakeTurnsWithoutHoldingAWorker) {
  // Two renderers that cannot render concurrently, on one device: never at
  // once. A CPU job queued behind them starts while they wait.
  Metrics metrics;
  RenderService::Options options;
  options.workers = 2;
  RenderService service(noBuilds, options, metrics);
  Outcomes outcomes;
  const auto gate = std::make_shared<Gate>();
  service.submit(job(stuckOn("gpu0", "gbuffer", gate), outcomes, "a"));
  ASSERT_TRUE(waitUntil([&] { return service.pixelsInFlight() == 64; }));
  service.submit(job(stuckOn("gpu0", "gbuffer", gate), outcomes, "b"));  // another renderer, the same device
  service.submit(job(cpu(), outcomes, "cpu"));
  ASSERT_TRUE(waitUntil([&] { return !outcomes.of("cpu").empty(); }));
  // b has not started: a's pixels alone. (The cpu frame is answered from an
  // encode thread, maybe before its worker has given its pixels back; b,
  // had it started, would hold its own at the gate for good.)
  EXPECT_TRUE(waitUntil([&] { return service.pixelsInFlight() == 64; })) << service.pixelsInFlight();
  EXPECT_EQ(service.queued(), 1u);
  gate->release();
  ASSERT_TRUE(waitUntil([&] { return !outcomes.of("a").empty() && !outcomes.of("b").empty(); }));
  EXPECT_EQ(outcomes.of("b"), std::vector<std::string>{"frame"});
}

TEST(FrameDeadline, MetricsNameEachDeviceAndItsHealth) {
  Metrics metrics;
  metrics.framesAbandoned = 2;
  metrics.renderThreadsStuck = 1;
  metrics.setDevices({{"vulkan", "llvmpipe (LLVM 15.0.6, \"256\" bits)", false}, {"cpu", "cpu0", true}});
  const std::string text = metrics.prometheusText();
  EXPECT_NE(text.find("haarcast_device_healthy{backend=\"vulkan\",device=\"llvmpipe (LLVM 15.0.6, \\\"256\\\" bits)\"} 0\n"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("haarcast_device_healthy{backend=\"cpu\",device=\"cpu0\"} 1\n"), std::string::npos);
  EXPECT_NE(text.find("\nhaarcast_frames_abandoned_total 2\n"), std::string::npos);
  EXPECT_NE(text.find("\nhaarcast_render_threads_stuck 1\n"), std::string::npos);
}

}  // namespace
}  // namespace haarcast::net
