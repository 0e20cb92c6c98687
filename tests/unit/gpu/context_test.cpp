// Device selection, errors that name the call, buffers and a trivial
// pipeline round trip.
#include <gtest/gtest.h>

#include <numeric>
#include <optional>
#include <span>
#include <stdexcept>
#include <vector>

#include "gpu_test_util.h"
#include "haarcast/gpu/buffer.h"
#include "haarcast/gpu/compute.h"
#include "haarcast/gpu/context.h"
#include "haarcast/gpu/memory.h"
#include "haarcast/gpu/shaders.h"

namespace haarcast::gpu {
namespace {

GPU_TEST(VulkanContext, ErrorsNameTheCallAndTheCode) {
  try {
    vkCheck(VK_ERROR_OUT_OF_DEVICE_MEMORY, "vkAllocateMemory");
    FAIL() << "vkCheck did not throw";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "vkAllocateMemory failed: VK_ERROR_OUT_OF_DEVICE_MEMORY (-2)");
  }
  EXPECT_NO_THROW(vkCheck(VK_SUCCESS, "vkCreateDevice"));
}

GPU_TEST(VulkanContext, EveryShaderIsEmbedded) {
  for (const char* name : {"rotate_spatial.comp", "rotation_input.comp", "triple_product.comp", "resolve.comp",
                           "exposure.comp", "tonemap.comp", "fused.comp", "splitsum.comp", "shared_layout_check.comp",
                           "shared_functions_check.comp",
                           "gbuffer.vert", "gbuffer.frag"}) {
    const auto words = embeddedShader(name);
    ASSERT_GT(words.size(), 5u) << name;
    EXPECT_EQ(words[0], 0x07230203u) << name << ": not SPIR-V (magic)";
  }
  EXPECT_TRUE(embeddedShader("no_such.comp").empty());
}

GPU_TEST(VulkanContext, ListsDevicesAndSelectsOne) {
  HAARCAST_REQUIRE_VULKAN();
  const auto devices = listDevices();
  ASSERT_FALSE(devices.empty());
  Context context(testing::testOptions());
  EXPECT_TRUE(context.info().rejected.empty());
  EXPECT_FALSE(context.info().name.empty());
  EXPECT_NE(describeDevices(devices).find(context.info().name), std::string::npos);
  // Selecting by index and by name finds the same device.
  Context byIndex(VulkanOptions{std::to_string(context.info().index), false});
  EXPECT_EQ(byIndex.info().name, context.info().name);
  Context byName(VulkanOptions{context.info().name.substr(0, 4), false});
  EXPECT_EQ(byName.info().index, context.info().index);
  EXPECT_EQ(context.validationEnabled(), validationLayerInstalled());
  testing::expectNoValidationMessages(context);
}

GPU_TEST(VulkanContext, UnknownDeviceListsEveryDeviceAndWhy) {
  HAARCAST_REQUIRE_VULKAN();
  try {
    Context context(VulkanOptions{"no-such-gpu-xyz", false});
    FAIL() << "selected a device that does not exist";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no-such-gpu-xyz"), std::string::npos) << what;
    EXPECT_NE(what.find(listDevices().front().name), std::string::npos) << what;
    EXPECT_NE(what.find("does not match"), std::string::npos) << what;
  }
}

GPU_TEST(VulkanContext, BufferRoundTripAndBoundsCheck) {
  HAARCAST_REQUIRE_VULKAN();
  Context context(testing::testOptions());
  Buffer b(context, 64);
  std::vector<float> in(16), out(16);
  std::iota(in.begin(), in.end(), 1.0f);
  b.upload(std::span<const float>(in));
  b.download(std::span<float>(out));
  EXPECT_EQ(in, out);
  EXPECT_THROW(b.write(in.data(), 64, 4), std::out_of_range);
  EXPECT_THROW(ComputePipeline(context, "missing.comp", 1, 0), std::invalid_argument);
  testing::expectNoValidationMessages(context);
}

// Device inputs (buffer.h): mapped where the host sees all of device-local
// memory (lavapipe does), else staged; the staged path, forced on any device,
// delivers what was written, piece by piece, and refuses host access.
GPU_TEST(VulkanContext, DeviceInputsMappedOrStaged) {
  HAARCAST_REQUIRE_VULKAN();
  Context direct(testing::testOptions());
  const std::optional<MemoryPlacement> where =
      chooseMemory(direct.memoryProperties(), ~0u, MemoryUse::DeviceInput);
  ASSERT_TRUE(where.has_value());
  Buffer mapped(direct, 64, kStorageUsage, MemoryUse::DeviceInput);
  EXPECT_EQ(mapped.staged(), where->staged);
  EXPECT_EQ(mapped.mapped() != nullptr, where->mapped);

  VulkanOptions options = testing::testOptions();
  options.stageInputs = true;
  Context context(options);
  Buffer target(context, 64, kStorageUsage, MemoryUse::DeviceInput);
  EXPECT_TRUE(target.staged());
  EXPECT_EQ(target.mapped(), nullptr);
  std::vector<float> in(16), out(16, -1.0f);
  std::iota(in.begin(), in.end(), 1.0f);
  EXPECT_THROW(target.write(in.data(), 4), std::logic_error);
  BufferUpload upload(context, target);
  EXPECT_TRUE(upload.staged());
  EXPECT_FALSE(upload.pending());
  upload.write(in.data() + 8, 32, 32);  // the second half first
  upload.write(in.data(), 32, 0);
  EXPECT_TRUE(upload.pending());
  EXPECT_THROW(upload.write(in.data(), 64, 4), std::out_of_range);
  upload.submit();
  EXPECT_FALSE(upload.pending());
  Buffer readback(context, 64);
  context.submit([&](VkCommandBuffer cb) {
    const VkBufferCopy all{0, 0, 64};
    vkCmdCopyBuffer(cb, target.handle(), readback.handle(), 1, &all);
    computeBarrier(cb);
  });
  readback.download(std::span<float>(out));
  EXPECT_EQ(in, out);
  testing::expectNoValidationMessages(direct);
  testing::expectNoValidationMessages(context);
}

}  // namespace
}  // namespace haarcast::gpu
