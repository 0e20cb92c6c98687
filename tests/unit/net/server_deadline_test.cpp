// A render that never returns, seen from outside the server: the session's
// Error names the stage, /readyz turns 503 naming the default backend's
// device, /metrics counts it, and the server stops within 2 s without
// joining the stuck thread (frame_workers.h).
#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>

#include "haarcast/render/frame_stage.h"
#include "server_fixture.h"

namespace haarcast::net::test {
namespace {

// Renders that have reached their hang: a test that needs one stuck waits
// for this to grow (the pixels are reserved before the render starts).
std::atomic<int> hangingRenders{0};

// Blocks for ever in stage gbuffer, deaf to cancellation: a hung driver call.
class HangingRenderer final : public render::Renderer {
 public:
  explicit HangingRenderer(std::size_t objects) : objects_(objects) {}
  std::string backend() const override { return "cpu"; }  // the default backend's
  std::string deviceName() const override { return "hanging cpu"; }
  const render::RenderOptions& options() const override { return options_; }
  std::size_t objectCount() const override { return objects_; }
  bool concurrentRenders() const override { return true; }
  render::Frame render(const render::FrameRequest& request) override {
    render::enterFrameStage(request, "light");
    render::enterFrameStage(request, "gbuffer");
    std::unique_lock lock(mutex_);
    ++hangingRenders;
    never_.wait(lock, [] { return false; });
    return {};
  }

 private:
  render::RenderOptions options_;
  std::size_t objects_;
  std::mutex mutex_;
  std::condition_variable never_;
};

AbandonableRendererBuilder hangingBuilder() {
  return [](const SessionConfig&, const std::function<bool()>&, const render::RenderProgress&) {
    auto p = std::make_shared<PreparedRenderer>();
    p->renderer = std::make_unique<HangingRenderer>(render::defaultScene().objects.size());
    return p;
  };
}

double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

TEST(ServerFrameDeadline, TheErrorReadyzAndMetricsNameTheStuckDevice) {
  auto options = testOptions();
  options.render.frameDeadlineSeconds = 0.3;
  auto server = std::make_unique<Server>(options, testCatalog(render::defaultScene()), hangingBuilder());
  server->start();
  const auto port = server->port();
  http::status status{};
  httpGet(port, "/readyz", &status);
  EXPECT_EQ(status, http::status::ok);
  {
    Client c(port);
    c.handshake();
    c.send(pose(1));
    const v1::Error error = c.expectError(v1::ERROR_CODE_RENDER_FAILED, false);
    EXPECT_EQ(error.message(), "frame abandoned after 0.3 s in stage gbuffer on device hanging cpu (frame-deadline); "
                               "the device is marked unhealthy");
  }
  EXPECT_EQ(httpGet(port, "/readyz", &status),
            "device unhealthy: hanging cpu (cpu): a frame abandoned after 0.3 s in stage gbuffer\n");
  EXPECT_EQ(status, http::status::service_unavailable);
  EXPECT_TRUE(server->atCapacity());  // gRPC health follows it
  EXPECT_EQ(metric(port, "haarcast_device_healthy{backend=\"cpu\",device=\"hanging cpu\"}"), 0);
  EXPECT_EQ(metric(port, "haarcast_frames_abandoned_total"), 1);
  EXPECT_EQ(metric(port, "haarcast_render_threads_stuck"), 1);
  EXPECT_EQ(metric(port, "haarcast_pixels_in_flight"), 0);
  EXPECT_EQ(httpGet(port, "/healthz", &status), "ok\n");  // the process still serves
  const auto t0 = Clock::now();
  server->stop();
  server->wait();
  server.reset();
  EXPECT_LT(secondsSince(t0), 2.0);
}

TEST(ServerFrameDeadline, StopReturnsWithinTwoSecondsWithARenderStuck) {
  auto options = testOptions();
  options.render.frameDeadlineSeconds = 0;  // none: the render is still stuck at stop
  auto server = std::make_unique<Server>(options, testCatalog(render::defaultScene()), hangingBuilder());
  server->start();
  const auto port = server->port();
  const int before = hangingRenders.load();
  Client c(port);
  c.handshake();
  c.send(pose(1));
  const auto deadline = Clock::now() + 10s;
  while (hangingRenders.load() == before && Clock::now() < deadline) std::this_thread::sleep_for(10ms);
  ASSERT_GT(hangingRenders.load(), before);  // the render is inside its hang, not about to start
  ASSERT_GT(metric(port, "haarcast_pixels_in_flight"), 0);
  const auto t0 = Clock::now();
  server->stop();
  c.expectError(v1::ERROR_CODE_SHUTTING_DOWN, true);
  server->wait();
  server.reset();  // the render service's stop: its grace counts from stop()
  const double took = secondsSince(t0);
  EXPECT_LT(took, 2.0);
  EXPECT_GE(took, 1.4);  // it did give the render its grace
}

}  // namespace
}  // namespace haarcast::net::test
