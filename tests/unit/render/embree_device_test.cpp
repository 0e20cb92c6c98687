// Every RayScene of a process shares one Embree device (embree_scene.h):
// scenes built, traced and dropped on several threads at once make no
// second device, and each still answers for its own geometry.
#include <gtest/gtest.h>

#include <string>
#include <thread>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "haarcast/assets/procedural_mesh.h"
#include "haarcast/render/embree_scene.h"

namespace haarcast {
namespace {

TEST(EmbreeDevice, EveryRaySceneSharesOne) {
  const Mesh sphere = assets::makeSphere(12);
  constexpr int kThreads = 4, kScenes = 50;
  std::vector<std::string> failures(kThreads);
  {
    std::vector<std::jthread> threads;
    for (int t = 0; t < kThreads; ++t) {
      threads.emplace_back([&, t] {
        for (int i = 0; i < kScenes; ++i) {
          // Each scene's sphere elsewhere: a ray through its place is blocked, one beside it is not.
          const float x = static_cast<float>(10 * t + i % 10);
          const RayScene scene({Instance{&sphere, glm::translate(glm::mat4(1.0f), {x, 0.0f, 0.0f})}});
          const bool through = scene.occluded(Ray{{x, 0.0f, 5.0f}, {0.0f, 0.0f, -1.0f}});
          const bool beside = scene.occluded(Ray{{x + 3.0f, 0.0f, 5.0f}, {0.0f, 0.0f, -1.0f}});
          if (!through || beside) {
            failures[static_cast<std::size_t>(t)] = "scene " + std::to_string(i) + " answers for another's geometry";
            return;
          }
        }
      });
    }
  }
  for (int t = 0; t < kThreads; ++t) EXPECT_EQ(failures[static_cast<std::size_t>(t)], "") << "thread " << t;
  EXPECT_EQ(RayScene::devicesCreated(), 1u);
}

}  // namespace
}  // namespace haarcast
