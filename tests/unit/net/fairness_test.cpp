// Issue 12's fairness tests, each with a well-behaved client alongside: a
// large frame whose client disconnects is cancelled, stop() during a large
// frame returns at once, and a settings flood from one session does not hold
// back another session's Welcome.
//
// The large frame's cost comes from a test renderer: frames over 32×32 take
// seconds, polled for cancellation every couple of milliseconds as the CPU
// backend does at each tile (render::FrameRequest::cancelled); smaller ones
// render with the real CPU renderer. So the tests measure the server's
// cancellation, not how fast this machine renders 256².
#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

#include "server_fixture.h"

namespace haarcast::net::test {
namespace {

constexpr int kSmallSide = 32;
constexpr auto kLargeFrameTime = 20s;  // what a large frame costs when nobody cancels it

// Large frames: kLargeFrameTime in 2 ms steps, or until cancelled.
class LargeFramesAreSlow final : public render::Renderer {
 public:
  LargeFramesAreSlow(std::unique_ptr<render::Renderer> real, std::atomic<int>& started)
      : real_(std::move(real)), started_(started) {}
  std::string backend() const override { return real_->backend(); }
  std::string deviceName() const override { return real_->deviceName(); }
  const render::RenderOptions& options() const override { return real_->options(); }
  std::size_t objectCount() const override { return real_->objectCount(); }
  bool concurrentRenders() const override { return real_->concurrentRenders(); }
  render::Frame render(const render::FrameRequest& request) override {
    if (request.width * request.height <= kSmallSide * kSmallSide) return real_->render(request);
    started_.fetch_add(1);
    const auto end = Clock::now() + kLargeFrameTime;
    while (Clock::now() < end) {
      if (request.cancelled && request.cancelled()) {
        render::Frame f;
        f.width = request.width;
        f.height = request.height;
        f.cancelled = true;
        return f;
      }
      std::this_thread::sleep_for(2ms);
    }
    return real_->render(request);
  }

 private:
  std::unique_ptr<render::Renderer> real_;
  std::atomic<int>& started_;
};

ServerOptions oneWorker() {
  ServerOptions o = testOptions();
  // One render thread: without cancellation the large frame would hold it,
  // and every other session's frames would wait for it.
  o.render.workers = 1;
  o.limits.maxFps = 60;
  return o;
}

std::unique_ptr<Server> slowLargeFrameServer(ServerOptions options, std::atomic<int>& largeStarted) {
  RendererBuilder real = testBuilder();
  RendererBuilder builder = [real, &largeStarted](const SessionConfig& c) {
    auto p = real(c);
    p->renderer = std::make_unique<LargeFramesAreSlow>(std::move(p->renderer), largeStarted);
    return p;
  };
  auto server = std::make_unique<Server>(std::move(options), testCatalog(render::defaultScene()), builder);
  server->start();
  return server;
}

bool waitFor(const std::function<bool()>& condition, std::chrono::milliseconds limit = 10s) {
  const auto end = Clock::now() + limit;
  while (!condition()) {
    if (Clock::now() > end) return false;
    std::this_thread::sleep_for(1ms);
  }
  return true;
}

// Pose → Frame round trip of a session, in seconds.
double frameTime(Client& c, std::uint64_t sequence) {
  const auto t0 = Clock::now();
  c.send(pose(sequence, static_cast<double>(sequence)));
  EXPECT_TRUE(c.expect(v1::ServerMessage::kFrame, 30s)) << "no frame for pose " << sequence;
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

TEST(ServerFairness, LargeFrameOfAClientThatLeftIsCancelled) {
  std::atomic<int> largeStarted{0};
  auto server = slowLargeFrameServer(oneWorker(), largeStarted);
  const auto port = server->port();

  Client healthy(port);
  healthy.handshake(hello(kSmallSide, kSmallSide, v1::ENCODING_JPEG, 60));
  ASSERT_TRUE(healthy.expect(v1::ServerMessage::kFrame));
  // Its own frame time, with nobody else on the server: the median of a few.
  std::uint64_t sequence = 1;
  std::vector<double> alone;
  for (int i = 0; i < 7; ++i) {
    std::this_thread::sleep_for(30ms);  // past the 60 fps pacing: the round trip alone
    alone.push_back(frameTime(healthy, ++sequence));
  }
  std::sort(alone.begin(), alone.end());
  const double own = alone[alone.size() / 2];

  {
    Client large(port);
    large.handshake(hello(256, 256, v1::ENCODING_JPEG, 60));
    ASSERT_TRUE(waitFor([&] { return largeStarted.load() >= 1; })) << "the large frame never started";
    large.vanish();  // gone mid-frame, without a close handshake
  }
  std::this_thread::sleep_for(30ms);
  const double after = frameTime(healthy, ++sequence);
  std::printf("healthy client's frame: %.1f ms alone, %.1f ms after the large client left\n", own * 1e3, after * 1e3);
  EXPECT_LE(after, 2.0 * own + 0.01)
      << "the healthy client's frame took " << after * 1e3 << " ms after the large client left; alone "
      << own * 1e3 << " ms (the large frame was not cancelled?)";
  EXPECT_TRUE(waitFor([&] { return server->metrics().framesCancelled.load() >= 1; }, 2s));
  server->stop();
  server->wait();
}

TEST(ServerFairness, StopDuringALargeFrameReturnsWithinTwoSeconds) {
  std::atomic<int> largeStarted{0};
  auto server = slowLargeFrameServer(oneWorker(), largeStarted);
  const auto port = server->port();
  Client large(port);
  large.handshake(hello(256, 256, v1::ENCODING_JPEG, 60));
  ASSERT_TRUE(waitFor([&] { return largeStarted.load() >= 1; })) << "the large frame never started";
  // The client reads, as a well-behaved one does, so it answers the close.
  std::thread reader([&] { large.expectError(v1::ERROR_CODE_SHUTTING_DOWN, true); });
  const auto t0 = Clock::now();
  server->stop();
  server->wait();
  server.reset();  // joins the render and encode threads
  const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  reader.join();
  EXPECT_LT(seconds, 2.0) << "stop() during a large frame took " << seconds << " s";
}

// A settings flood: 200 RenderSettings, each a renderer of its own (level ×
// method), from one session. Per session only the latest build waits, so a
// new client waits at most for the one build running when it arrives, then
// its own: the builds finished between its Hello and its Welcome are ≤ 2.
TEST(ServerFairness, SettingsFloodDoesNotHoldBackAnotherWelcome) {
  auto options = testOptions();
  options.limits.maxLevel = 4;
  TestServer server(options);
  const auto port = server.port();
  Client flood(port);
  flood.handshake();
  const v1::RotationMethod methods[] = {v1::ROTATION_METHOD_HAAR, v1::ROTATION_METHOD_FUSED,
                                        v1::ROTATION_METHOD_SPATIAL};
  for (int i = 0; i < 200; ++i) {
    v1::ClientMessage m;
    m.mutable_settings()->set_level(static_cast<std::uint32_t>(2 + i % 3));
    m.mutable_settings()->set_method(methods[(i / 3) % 3]);
    flood.send(m);
  }
  const std::uint64_t builtBefore = server.server().metrics().renderersBuilt.load();
  Client late(port);
  // A renderer nobody has: its own build is needed.
  auto h = hello();
  h.mutable_hello()->mutable_scene()->mutable_object_materials()->insert({0, "lambert"});
  late.handshake(h);
  const std::uint64_t builtAfter = server.server().metrics().renderersBuilt.load();
  EXPECT_LE(builtAfter - builtBefore, 2u)
      << "the new client's Welcome waited for " << (builtAfter - builtBefore) << " renderer builds";
  // The flooding session is not cut: it gets its latest renderer's frames.
  flood.send(pose(1));
  EXPECT_TRUE(flood.expect(v1::ServerMessage::kFrame, 30s));
}

}  // namespace
}  // namespace haarcast::net::test
