// A server on the Vulkan backend whose client keeps changing settings: each
// change a renderer the LRU does not hold, so the builder makes a new
// Vulkan renderer every time (with backends::makeRenderer, as `serve` does). The process still makes one VkInstance and one
// VkDevice (gpu/engine.h): before the engine, each renderer made its own, and
// NVIDIA's driver refuses instances after about 40 in one process. The
// tiniest frame (16×16) and the lowest levels keep 100 builds quick on
// lavapipe (the time is printed).
#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "haarcast/gpu/engine.h"
#include "haarcast/render/embree_scene.h"
#include "server_fixture.h"

// The sanitized build (deploy/sanitize_build.sh) runs the net tests but no
// GPU work: lavapipe and the Vulkan loader are not instrumented.
#if defined(__SANITIZE_ADDRESS__)
#define HAARCAST_ENGINE_REUSE_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define HAARCAST_ENGINE_REUSE_SANITIZED 1
#endif
#endif

namespace haarcast::net::test {
namespace {

struct Setting {
  v1::RotationMethod method;
  std::uint32_t level;
};
// Five configurations for an LRU of four (RenderService::Options::
// maxRenderers): taken in turn, each one is the least recently used, so
// every change is a build.
// The rotating methods at the lowest levels: `fused` and `splitsum` build
// their prefiltered light and measure their lobes at every build (about a
// second on two cores), which would be most of the test's time.
constexpr std::array<Setting, 5> kSettings = {{{v1::ROTATION_METHOD_SPATIAL, 2},
                                               {v1::ROTATION_METHOD_HAAR, 2},
                                               {v1::ROTATION_METHOD_SPATIAL, 3},
                                               {v1::ROTATION_METHOD_HAAR, 3},
                                               {v1::ROTATION_METHOD_MATRIX, 2}}};

// The server fixture's builder (testBuilder) on one default scene whose
// environment maps are made once per level, not per build: the procedural
// sky's level-9 backdrop is evaluated point by point.
RendererBuilder sharedSceneBuilder(std::shared_ptr<std::atomic<int>> builds) {
  auto scene = std::make_shared<render::Scene>(render::defaultScene());
  auto made = std::make_shared<std::map<int, std::array<SphereMap, 3>>>();
  auto mutex = std::make_shared<std::mutex>();
  scene->environment.maps = [make = scene->environment.maps, made, mutex](int level) {
    std::lock_guard lock(*mutex);
    auto it = made->find(level);
    if (it == made->end()) it = made->emplace(level, make(level)).first;
    return it->second;
  };
  return [scene, builds](const SessionConfig& c) {
    ++*builds;
    const render::RenderOptions options = testRenderOptions(c);
    auto p = std::make_shared<PreparedRenderer>();
    p->renderer = backends::makeRenderer(backendName(c.backend), *scene, options);
    return p;
  };
}

v1::ClientMessage settingsMessage(const Setting& s) {
  v1::ClientMessage m;
  m.mutable_settings()->set_method(s.method);
  m.mutable_settings()->set_level(s.level);
  m.mutable_settings()->set_backend(v1::BACKEND_VULKAN);
  return m;
}

TEST(EngineReuse, HundredSettingsChangesOnVulkanMakeOneInstance) {
#ifdef HAARCAST_ENGINE_REUSE_SANITIZED
  GTEST_SKIP() << "sanitized build: the GPU tests run in the ordinary build";
#endif
  if (!gpu::vulkanAvailable()) GTEST_SKIP() << "no Vulkan device";
  Catalog catalog = testCatalog(render::defaultScene());
  catalog.backends = {Backend::Cpu, Backend::Vulkan};
  auto builds = std::make_shared<std::atomic<int>>(0);
  ServerOptions options = testOptions();
  options.statsSeconds = 60;  // no Stats between the frames this test waits for
  Server server(options, std::move(catalog), sharedSceneBuilder(builds));
  server.start();

  const auto start = Clock::now();
  Client c(server.port());
  ASSERT_TRUE(c.connected());
  v1::ClientMessage h = hello(16, 16);
  *h.mutable_hello()->mutable_settings() = settingsMessage(kSettings[0]).settings();
  c.handshake(h);
  std::uint64_t sequence = 0;
  constexpr int kChanges = 100;
  for (int change = 1; change <= kChanges; ++change) {
    const Setting& want = kSettings[static_cast<std::size_t>(change) % kSettings.size()];
    c.send(settingsMessage(want));
    // A frame of the old renderer may still come; the new one's follows.
    bool seen = false;
    for (int attempt = 0; attempt < 10 && !seen; ++attempt) {
      ++sequence;
      c.send(pose(sequence, static_cast<double>(sequence)));
      const auto f = c.expect(v1::ServerMessage::kFrame);
      ASSERT_TRUE(f) << "no frame after change " << change;
      const v1::RenderSettings& got = f->frame().settings();
      seen = got.method() == want.method && got.level() == want.level && got.backend() == v1::BACKEND_VULKAN;
    }
    ASSERT_TRUE(seen) << "change " << change << ": no frame with the new settings";
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  std::printf("%d settings changes, %d Vulkan renderers built, in %.1f s: %llu VkInstance, %llu VkDevice, "
              "%llu Embree device\n",
              kChanges, builds->load(), seconds, static_cast<unsigned long long>(gpu::Engine::instancesCreated()),
              static_cast<unsigned long long>(gpu::Engine::devicesCreated()),
              static_cast<unsigned long long>(RayScene::devicesCreated()));
  EXPECT_EQ(builds->load(), kChanges + 1);  // the Hello's and one per change
  EXPECT_EQ(gpu::Engine::instancesCreated(), 1u);
  EXPECT_EQ(gpu::Engine::devicesCreated(), 1u);
  EXPECT_LE(RayScene::devicesCreated(), 1u);
}

}  // namespace
}  // namespace haarcast::net::test
