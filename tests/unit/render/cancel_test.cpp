// The CPU backend under a server's load: frames cancelled at the next row,
// and concurrent frames on one prepared renderer.
#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/render/renderer.h"

#include <algorithm>
#include <atomic>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "haarcast/assets/procedural_mesh.h"

namespace haarcast::render {
namespace {

constexpr unsigned kThreads = 4;  // the renderer's own threads: the rows in flight at a cancel, at most

RenderOptions smallOptions() {
  RenderOptions o;
  o.level = 4;
  o.thetaSamples = 4;
  o.sliceSupersampling = 2;
  o.visibility.supersampling = 1;
  o.lightCoefficients = 64;
  o.threads = kThreads;
  return o;
}

Scene torusScene() {
  Scene s;
  s.environment = builtinEnvironment();
  s.objects.push_back({"torus", std::make_shared<Mesh>(assets::makeTorus(0.6, 0.25, 24, 12)), materialFromSpec("phong:16"), {}});
  s.camera.eye = {0.0, 0.3, 2.6};
  return s;
}

FrameRequest tallRequest(const Scene& scene) {
  FrameRequest r;
  r.width = 16;
  r.height = 200;  // many rows: each a tile of every per-row pass
  r.camera = scene.camera;
  return r;
}

// A predicate that turns true after `after` polls and counts the polls made
// once it has (the rows that still asked after the cancel).
struct CountingCancel {
  explicit CountingCancel(long threshold) : after(threshold) {}
  long after;
  std::atomic<long> polls{0};
  std::atomic<long> pollsAfterCancel{0};
  bool operator()() {
    if (polls.fetch_add(1) < after) return false;
    pollsAfterCancel.fetch_add(1);
    return true;
  }
};

TEST(CpuBackend, EveryRowOfEveryPassPollsTheCancelAndAnUncancelledFrameIsUnchanged) {
  const Scene scene = torusScene();
  const auto renderer = makeCpuRenderer(scene, smallOptions());
  FrameRequest request = tallRequest(scene);
  const Frame plain = renderer->render(request);
  CountingCancel never(1L << 40);
  request.cancelled = [&] { return never(); };
  const Frame polled = renderer->render(request);
  EXPECT_FALSE(polled.cancelled);
  EXPECT_EQ(polled.rgba8, plain.rgba8);
  // Four passes run row by row: gbuffer, rotation-input, shading and the
  // backdrop; each row is a tile boundary.
  EXPECT_GE(never.polls.load(), 4L * request.height);
}

// A watched frame's stage fractions (frame_stage.h), as the server's
// FrameProgress reads them: each tile polls the cancel, then ticks, so a
// poll sees at most tiles − 1 ticks of its stage. A stage whose count is
// right is seen nearly done (≥ 0.95 of 200 rows) and never whole; one that
// said too few tiles is seen whole early, one that said too many never
// gets near the end.
TEST(CpuBackend, EachStageOfAWatchedFrameCountsItsTilesToTheEnd) {
  const Scene scene = torusScene();
  for (const RotationMethod method : {RotationMethod::Haar, RotationMethod::Fused}) {
    RenderOptions options = smallOptions();
    options.method = method;
    const auto renderer = makeCpuRenderer(scene, options);
    FrameRequest request = tallRequest(scene);
    StageMark mark;
    request.stage = &mark;
    std::mutex mutex;
    std::map<std::string, double> seen;  // the largest fraction a poll saw, per stage
    request.cancelled = [&] {
      const char* stage = mark.current();
      const double fraction = mark.fraction();
      std::lock_guard lock(mutex);
      double& most = seen[stage ? stage : "none"];
      most = std::max(most, fraction);
      return false;
    };
    EXPECT_FALSE(renderer->render(request).cancelled);
    const char* shading = method == RotationMethod::Fused ? "fused" : "rotation";
    for (const char* stage : {"gbuffer", "rotation-input", shading, "tonemap"}) {
      ASSERT_TRUE(seen.count(stage)) << stage;
      EXPECT_GE(seen[stage], 0.95) << methodName(method) << " " << stage;
      EXPECT_LT(seen[stage], 1.0) << methodName(method) << " " << stage;
    }
  }
}

TEST(CpuBackend, ACancelledFrameStopsAtTheRowsInFlight) {
  const Scene scene = torusScene();
  const auto renderer = makeCpuRenderer(scene, smallOptions());
  const FrameRequest base = tallRequest(scene);
  // Cancelled in each of the four row passes in turn.
  for (const long after : {base.height / 2L, 3L * base.height / 2, 5L * base.height / 2, 7L * base.height / 2}) {
    CountingCancel cancel(after);
    FrameRequest request = base;
    request.cancelled = [&] { return cancel(); };
    const Frame f = renderer->render(request);
    EXPECT_TRUE(f.cancelled) << "cancelled after " << after << " polls";
    EXPECT_TRUE(f.rgba8.empty());
    EXPECT_TRUE(f.image.rgb.empty());
    // The thread that saw the cancel stops; each other thread finishes the
    // row it holds and stops at its next poll.
    EXPECT_LE(cancel.pollsAfterCancel.load(), static_cast<long>(kThreads)) << "cancelled after " << after << " polls";
  }
  // The renderer is whole after cancelled frames.
  EXPECT_EQ(renderer->render(base).rgba8, makeCpuRenderer(scene, smallOptions())->render(base).rgba8);
}

TEST(CpuBackend, ConcurrentFramesOnOneRendererEqualSerialOnes) {
  const Scene scene = torusScene();
  const auto renderer = makeCpuRenderer(scene, smallOptions());
  EXPECT_TRUE(renderer->concurrentRenders());
  // Two poses: each frame poses the object in its ray scene, so frames that
  // shared one would see each other's pose.
  std::vector<FrameRequest> requests(2, tallRequest(scene));
  for (FrameRequest& r : requests) r.height = 48;
  requests[0].poses = {Pose{{0.0, 0.0, 0.0}, {-0.3, 0.0, 0.0}, 1.0}};
  requests[1].poses = {Pose{{70.0, 30.0, 0.0}, {0.3, 0.2, 0.0}, 0.8}};
  std::vector<std::vector<std::uint8_t>> serial;
  for (const FrameRequest& r : requests) serial.push_back(renderer->render(r).rgba8);
  ASSERT_NE(serial[0], serial[1]);
  constexpr int kRounds = 12;
  std::atomic<int> mismatches{0};
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < kRounds; ++i) {
        if (renderer->render(requests[t % 2]).rgba8 != serial[t % 2]) ++mismatches;
      }
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(mismatches.load(), 0);
}

}  // namespace
}  // namespace haarcast::render
