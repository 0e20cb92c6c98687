// One engine per process (engine.h): however many renderers, Contexts and
// device queries a process makes, it makes one VkInstance and one VkDevice;
// Contexts on the shared queue submit from many threads at once; the
// validation log reads from a mark.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <set>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "frame_compare.h"
#include "gpu_test_util.h"
#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/gpu/vulkan_renderer.h"
#include "haarcast/gpu/buffer.h"
#include "haarcast/gpu/compute.h"
#include "haarcast/gpu/engine.h"

namespace haarcast::gpu {
namespace {

TEST(ValidationLog, AMarkReadsWhatCameAfterItAndOnlyTheLatestAreKept) {
  ValidationLog log;
  EXPECT_EQ(log.count(), 0u);
  EXPECT_TRUE(log.since(0).empty());
  log.add("a");
  const std::uint64_t mark = log.count();
  log.add("b");
  log.add("c");
  EXPECT_EQ(log.since(0), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(log.since(mark), (std::vector<std::string>{"b", "c"}));
  EXPECT_TRUE(log.since(log.count()).empty());
  for (std::size_t i = 0; i < ValidationLog::kKept + 10; ++i) log.add(std::to_string(i));
  EXPECT_EQ(log.count(), ValidationLog::kKept + 13);
  const std::vector<std::string> kept = log.since(0);  // the oldest are gone
  ASSERT_EQ(kept.size(), ValidationLog::kKept);
  EXPECT_EQ(kept.front(), "10");
  EXPECT_EQ(kept.back(), std::to_string(ValidationLog::kKept + 9));
  EXPECT_EQ(log.since(log.count() - 2), (std::vector<std::string>{std::to_string(ValidationLog::kKept + 8),
                                                                  std::to_string(ValidationLog::kKept + 9)}));
}

// The queries and every Context borrow the engine's instance and device;
// the test binary asked for validation first (gpu_test_util.h), so the
// instance has it wherever the layer is installed.
GPU_TEST(Engine, QueriesAndContextsBorrowOneInstanceAndOneDevice) {
  HAARCAST_REQUIRE_VULKAN();
  for (int i = 0; i < 50; ++i) {
    EXPECT_TRUE(vulkanAvailable());
    EXPECT_FALSE(listDevices().empty());
    const Context context(VulkanOptions{"", i % 2 == 0});  // validation asked or not: the instance decides
    EXPECT_EQ(context.instance(), Engine::get().instance());
  }
  const Context a(testing::testOptions()), b(testing::testOptions());
  EXPECT_EQ(a.device(), b.device());
  EXPECT_EQ(Engine::instancesCreated(), 1u);
  EXPECT_EQ(Engine::devicesCreated(), 1u);
  EXPECT_EQ(Engine::get().validationEnabled(), validationLayerInstalled());
  EXPECT_EQ(a.validationEnabled(), Engine::get().validationEnabled());
}

// Contexts on the shared device, one per thread, submit at once (the queue
// is locked around vkQueueSubmit only): each thread's buffer holds its own
// value after every round. Validation's thread checker reports a queue used
// from two threads at once, which the fixture turns into a failure (without
// the lock: in every one of 10 runs on lavapipe; the race is the checker's to see).
GPU_TEST(Engine, ContextsSubmitFromManyThreadsAtOnce) {
  HAARCAST_REQUIRE_VULKAN();
  constexpr int kThreads = 4, kRounds = 200;
  constexpr std::size_t kWords = 4096;
  std::vector<std::string> failures(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([t, &failures] {
      try {
        Context context(testing::testOptions());
        Buffer buffer(context, kWords * sizeof(std::uint32_t));
        std::vector<std::uint32_t> words(kWords);
        for (int round = 0; round < kRounds; ++round) {
          const std::uint32_t value = static_cast<std::uint32_t>(1000 * t + round);
          context.submit([&](VkCommandBuffer cb) {
            vkCmdFillBuffer(cb, buffer.handle(), 0, VK_WHOLE_SIZE, value);
            computeBarrier(cb);
          });
          buffer.download(std::span<std::uint32_t>(words));
          for (const std::uint32_t w : words) {
            if (w != value) {
              failures[static_cast<std::size_t>(t)] = "round " + std::to_string(round) + ": read " +
                                                      std::to_string(w) + ", wrote " + std::to_string(value);
              return;
            }
          }
        }
      } catch (const std::exception& e) {
        failures[static_cast<std::size_t>(t)] = e.what();
      }
    });
  }
  for (std::thread& t : threads) t.join();
  for (int t = 0; t < kThreads; ++t) EXPECT_EQ(failures[static_cast<std::size_t>(t)], "") << "thread " << t;
  EXPECT_EQ(Engine::instancesCreated(), 1u);
  EXPECT_EQ(Engine::devicesCreated(), 1u);
}

// Each Context is lent the least-lent of the device's queues, and gives it
// back when it goes (queue_lender.h): one more Context than the device has
// queues puts one Context on every queue, then shares the least-lent. On a
// device of one queue (lavapipe) every Context is lent queue 0.
GPU_TEST(Engine, EachContextIsLentTheLeastLentQueueAndGivesItBack) {
  HAARCAST_REQUIRE_VULKAN();
  const std::shared_ptr<SharedDevice> device =
      Engine::get().device(testing::testOptions().device, testing::testOptions().queues);
  ASSERT_GE(device->queueCount(), 1u);
  ASSERT_LE(device->queueCount(), kMaxDeviceQueues);
  const std::vector<std::size_t> before = device->queuesLent();
  ASSERT_EQ(before.size(), device->queueCount());
  {
    std::vector<std::unique_ptr<Context>> contexts;
    for (std::uint32_t i = 0; i <= device->queueCount(); ++i) {
      const std::vector<std::size_t> lent = device->queuesLent();
      const std::size_t least = *std::min_element(lent.begin(), lent.end());
      contexts.push_back(std::make_unique<Context>(testing::testOptions()));
      const std::uint32_t q = contexts.back()->queueIndex();
      ASSERT_LT(q, device->queueCount());
      EXPECT_EQ(lent[q], least) << "Context " << i << " was lent queue " << q;
      EXPECT_EQ(device->queuesLent()[q], lent[q] + 1);
      EXPECT_EQ(contexts.back()->queue(), device->queue(q));
      // It submits and waits on the queue it was lent.
      contexts.back()->submit([](VkCommandBuffer) {});
    }
  }
  EXPECT_EQ(device->queuesLent(), before);  // every one given back
}

// A renderer's frame slots are lent queues as Contexts are, one after
// another: K slots on K queues where the device has them (what lets its
// frames run side by side), all on queue 0 on lavapipe.
GPU_TEST(Engine, ARenderersFrameSlotsAreSpreadOverTheQueues) {
  HAARCAST_REQUIRE_VULKAN();
  const std::shared_ptr<SharedDevice> device =
      Engine::get().device(testing::testOptions().device, testing::testOptions().queues);
  render::RenderOptions options;
  options.method = RotationMethod::Spatial;
  options.level = 2;
  VulkanRendererLimits limits;
  limits.framesInFlight = 3;
  // The rule, from the queues' counts now: the least lent, lowest first.
  std::vector<std::size_t> counts = device->queuesLent();
  std::vector<std::uint32_t> want;
  for (int k = 0; k < 3; ++k) {
    const auto least = std::min_element(counts.begin(), counts.end());
    ++*least;
    want.push_back(static_cast<std::uint32_t>(least - counts.begin()));
  }
  VulkanRenderer renderer(render::defaultScene(), options, testing::testOptions(), {}, limits);
  EXPECT_EQ(renderer.slotQueues(), want);
  EXPECT_EQ(renderer.framesInFlight(), 3u);
  if (device->queueCount() >= 3) {
    EXPECT_EQ(std::set<std::uint32_t>(want.begin(), want.end()).size(), 3u);
  }
}

// The default scene with its environment's maps made once per level: the
// procedural sky's level-9 backdrop is evaluated point by point, which a
// test that builds renderers by the hundred need not pay each time.
render::Scene sceneWithMapsMadeOnce() {
  render::Scene scene = render::defaultScene();
  auto made = std::make_shared<std::map<int, std::array<SphereMap, 3>>>();
  scene.environment.maps = [make = scene.environment.maps, made](int level) {
    auto it = made->find(level);
    if (it == made->end()) it = made->emplace(level, make(level)).first;
    return it->second;
  };
  return scene;
}

// What a server does when clients keep changing settings: a renderer built,
// used and dropped, 200 times. The smallest real Vulkan renderer that is
// quick to prepare: the default scene at level 2, 16×16, `spatial` (`fused`
// would build its prefiltered light and measure its lobes each time, about
// a second); every frame against the CPU backend's.
GPU_TEST(Engine, TwoHundredRenderersMakeOneInstanceAndOneDevice) {
  HAARCAST_REQUIRE_VULKAN();
  const render::Scene scene = sceneWithMapsMadeOnce();
  render::RenderOptions o = testing::frameOptions(RotationMethod::Spatial, true);
  o.level = 2;
  o.width = o.height = 16;
  const render::FrameRequest request = testing::requestFor(scene, o.width, o.height);
  const render::Frame reference = render::makeCpuRenderer(scene, o)->render(request);
  const auto start = std::chrono::steady_clock::now();
  double worst = 1e300;
  constexpr int kRenderers = 200;
  for (int i = 0; i < kRenderers; ++i) {
    const auto renderer = makeVulkanRenderer(scene, o, testing::testOptions());
    const testing::Comparison c = testing::compare(reference, renderer->render(request));
    worst = std::min(worst, c.psnr);
    ASSERT_GE(c.psnr, 60.0) << "renderer " << i;
    ASSERT_EQ(c.mismatched, 0u) << "renderer " << i;
    ASSERT_GT(c.objectPixels, 20u) << "renderer " << i;
  }
  std::printf("%d Vulkan renderers built and rendered in %.1f s; worst PSNR against the CPU %.1f dB; "
              "instances %llu, devices %llu\n",
              kRenderers, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), worst,
              static_cast<unsigned long long>(Engine::instancesCreated()),
              static_cast<unsigned long long>(Engine::devicesCreated()));
  EXPECT_EQ(Engine::instancesCreated(), 1u);
  EXPECT_EQ(Engine::devicesCreated(), 1u);
}

}  // namespace
}  // namespace haarcast::gpu
