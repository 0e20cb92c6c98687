#include "haarcast/net/render_service.h"

#include <atomic>
#include <chrono>
#include <functional>
#include <future>
#include <mutex>
#include <thread>

#include <gtest/gtest.h>

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
  RenderJob gone;
  gone.renderer = fake;
  gone.take = [] { return std::optional<render::FrameRequest>(); };
  gone.done = [&](std::optional<RenderedFrame>, std::string) { firstDone = true; };
  service.submit(std::move(gone));
  RenderJob live;
  live.renderer = fake;
  live.take = [] { return request(4, 4); };
  live.done = [&](std::optional<RenderedFrame>, std::string) { second.set_value(); };
  service.submit(std::move(live));
  EXPECT_EQ(second.get_future().wait_for(5s), std::future_status::ready);
  EXPECT_FALSE(firstDone.load());
}

}  // namespace
}  // namespace haarcast::net
