// The backend registry (backends/backends.h): the names it offers are the
// ones this build has, an unknown or missing backend is an error naming the
// valid ones, and the factory makes the renderer each name says.
#include <gtest/gtest.h>

#include <functional>
#include <stdexcept>
#include <string>

#include "haarcast/backends/backends.h"
#include "haarcast/render/backend_names.h"
#include "haarcast/render/scene.h"

namespace haarcast {
namespace {

std::string messageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(Backends, TheBuildsBackendsAreListedInOrder) {
  const std::vector<std::string> names = backends::available();
  ASSERT_FALSE(names.empty());
  EXPECT_EQ(names.front(), render::kCpuBackend);  // every build has the CPU backend
  EXPECT_EQ(backends::built(render::kVulkanBackend), HAARCAST_TEST_HAS_VULKAN != 0);
  EXPECT_EQ(names.size(), HAARCAST_TEST_HAS_VULKAN ? 2u : 1u);
  EXPECT_EQ(backends::availableText(), HAARCAST_TEST_HAS_VULKAN ? "cpu, vulkan" : "cpu");
  EXPECT_NE(backends::buildDescription().find(backends::availableText()), std::string::npos);
}

TEST(Backends, AnUnknownOrMissingBackendIsAnErrorNamingTheValidOnes) {
  const std::string unknown = messageOf([] { backends::checkBuilt("gpu", "--backend"); });
  EXPECT_NE(unknown.find("--backend \"gpu\" is not a backend (valid: " + backends::availableText() + ")"), std::string::npos)
      << unknown;
  EXPECT_TRUE(messageOf([] { backends::checkBuilt(render::kCpuBackend); }).empty());
  const std::string vulkan = messageOf([] { backends::checkBuilt(render::kVulkanBackend, "--backend"); });
  if (HAARCAST_TEST_HAS_VULKAN) {
    EXPECT_TRUE(vulkan.empty()) << vulkan;
  } else {
    EXPECT_NE(vulkan.find("-DHAARCAST_VULKAN=OFF"), std::string::npos) << vulkan;
    EXPECT_NE(vulkan.find("backends in this build: cpu"), std::string::npos) << vulkan;
    EXPECT_TRUE(backends::vulkanDevices().empty());
  }
  render::Scene scene = render::defaultScene();
  render::RenderOptions options;
  options.level = 4;
  EXPECT_THROW(backends::makeRenderer("gpu", scene, options), std::invalid_argument);
}

TEST(Backends, TheFactoryMakesTheRendererItsNameSays) {
  const render::Scene scene = render::defaultScene();
  render::RenderOptions options;
  options.level = 4;
  options.cacheDir = "";
  const auto cpu = backends::makeRenderer(render::kCpuBackend, scene, options);
  ASSERT_NE(cpu, nullptr);
  EXPECT_EQ(cpu->backend(), render::kCpuBackend);
}

}  // namespace
}  // namespace haarcast
