// Buffer placement (gpu/memory.h) against the memory properties of the kinds
// of device there are, written out by hand, so that every path is checked
// without the device: lavapipe (one heap, one type that is everything), an
// integrated GPU, a discrete GPU with and without resizable BAR.
#include <gtest/gtest.h>

#include <initializer_list>
#include <utility>

#include "haarcast/gpu/memory.h"

namespace haarcast::gpu {
namespace {

constexpr VkMemoryPropertyFlags DL = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
constexpr VkMemoryPropertyFlags HV = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
constexpr VkMemoryPropertyFlags HC = VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
constexpr VkMemoryPropertyFlags CACHED = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
constexpr VkDeviceSize MiB = VkDeviceSize{1} << 20;
constexpr std::uint32_t kAllTypes = ~0u;

// heaps: (size, device-local); types: (flags, heap).
VkPhysicalDeviceMemoryProperties memoryOf(std::initializer_list<std::pair<VkDeviceSize, bool>> heaps,
                                          std::initializer_list<std::pair<VkMemoryPropertyFlags, std::uint32_t>> types) {
  VkPhysicalDeviceMemoryProperties m{};
  for (const auto& [size, local] : heaps) {
    m.memoryHeaps[m.memoryHeapCount++] = {size, local ? VkMemoryHeapFlags{VK_MEMORY_HEAP_DEVICE_LOCAL_BIT} : 0u};
  }
  for (const auto& [flags, heap] : types) m.memoryTypes[m.memoryTypeCount++] = {flags, heap};
  return m;
}

// Mesa lavapipe (vulkaninfo): one 2 GiB device-local heap, one type with every flag.
VkPhysicalDeviceMemoryProperties lavapipe() { return memoryOf({{2048 * MiB, true}}, {{DL | HV | HC | CACHED, 0}}); }

// An integrated GPU: one heap of shared memory, device-local, seen by the host.
VkPhysicalDeviceMemoryProperties integrated() {
  return memoryOf({{16384 * MiB, true}}, {{DL, 0}, {DL | HV | HC, 0}, {DL | HV | HC | CACHED, 0}});
}

// A discrete GPU without resizable BAR: 24 GiB of video memory, system
// memory, and a 256 MiB window of video memory the host can map.
VkPhysicalDeviceMemoryProperties discreteWithoutBar() {
  return memoryOf({{24576 * MiB, true}, {32768 * MiB, false}, {256 * MiB, true}},
                  {{0, 1}, {DL, 0}, {DL, 0}, {HV | HC, 1}, {HV | HC | CACHED, 1}, {DL | HV | HC, 2}});
}

// The same GPU with resizable BAR: the host-visible device-local type spans
// all of video memory.
VkPhysicalDeviceMemoryProperties discreteWithBar() {
  return memoryOf({{24576 * MiB, true}, {32768 * MiB, false}, {24576 * MiB, true}},
                  {{0, 1}, {DL, 0}, {DL, 0}, {HV | HC, 1}, {HV | HC | CACHED, 1}, {DL | HV | HC, 2}});
}

void expectPlacement(const std::optional<MemoryPlacement>& p, std::uint32_t type, bool mapped, bool staged) {
  ASSERT_TRUE(p.has_value());
  EXPECT_EQ(p->type, type);
  EXPECT_EQ(p->mapped, mapped);
  EXPECT_EQ(p->staged, staged);
}

TEST(MemoryPlacement, CpuDeviceMapsEverythingAndStagesOnlyWhenAsked) {
  const auto m = lavapipe();
  expectPlacement(chooseMemory(m, kAllTypes, MemoryUse::Host), 0, true, false);
  expectPlacement(chooseMemory(m, kAllTypes, MemoryUse::DeviceInput), 0, true, false);
  expectPlacement(chooseMemory(m, kAllTypes, MemoryUse::DeviceInput, false), 0, false, true);
  expectPlacement(chooseMemory(m, kAllTypes, MemoryUse::DeviceOnly), 0, false, false);
}

TEST(MemoryPlacement, IntegratedGpuMapsInputsInSharedMemory) {
  const auto m = integrated();
  expectPlacement(chooseMemory(m, kAllTypes, MemoryUse::Host), 1, true, false);
  expectPlacement(chooseMemory(m, kAllTypes, MemoryUse::DeviceInput), 1, true, false);
  expectPlacement(chooseMemory(m, kAllTypes, MemoryUse::DeviceOnly), 0, false, false);
}

TEST(MemoryPlacement, DiscreteGpuWithoutResizableBarStagesInputsIntoVideoMemory) {
  const auto m = discreteWithoutBar();
  // Inputs: video memory (type 1), not the 256 MiB window (type 5).
  expectPlacement(chooseMemory(m, kAllTypes, MemoryUse::DeviceInput), 1, false, true);
  expectPlacement(chooseMemory(m, kAllTypes, MemoryUse::DeviceOnly), 1, false, false);
  // Small per-frame uniforms and results: host-visible, the window first.
  expectPlacement(chooseMemory(m, kAllTypes, MemoryUse::Host), 5, true, false);
}

TEST(MemoryPlacement, DiscreteGpuWithResizableBarMapsInputsDirectly) {
  const auto m = discreteWithBar();
  expectPlacement(chooseMemory(m, kAllTypes, MemoryUse::DeviceInput), 5, true, false);
  expectPlacement(chooseMemory(m, kAllTypes, MemoryUse::DeviceInput, false), 1, false, true);
  expectPlacement(chooseMemory(m, kAllTypes, MemoryUse::DeviceOnly), 1, false, false);
}

// What the host reads back goes to cached system memory on a discrete GPU
// (the host reads a BAR window uncached, a bus round trip per load), and to
// the cached type wherever memory is one: lavapipe, an integrated GPU.
TEST(MemoryPlacement, ReadbackIsCachedAndOffTheCardWhereThereIsAChoice) {
  expectPlacement(chooseMemory(discreteWithBar(), kAllTypes, MemoryUse::Readback), 4, true, false);
  expectPlacement(chooseMemory(discreteWithoutBar(), kAllTypes, MemoryUse::Readback), 4, true, false);
  expectPlacement(chooseMemory(integrated(), kAllTypes, MemoryUse::Readback), 2, true, false);
  expectPlacement(chooseMemory(lavapipe(), kAllTypes, MemoryUse::Readback), 0, true, false);
  // Without a cached type: coherent system memory, then the BAR window.
  expectPlacement(chooseMemory(discreteWithBar(), (1u << 3) | (1u << 5), MemoryUse::Readback), 3, true, false);
  expectPlacement(chooseMemory(discreteWithBar(), 1u << 5, MemoryUse::Readback), 5, true, false);
  EXPECT_FALSE(chooseMemory(discreteWithBar(), (1u << 1) | (1u << 2), MemoryUse::Readback).has_value());
}

TEST(MemoryPlacement, OnlyTheTypesTheBufferAllows) {
  const auto m = discreteWithoutBar();
  // Only system memory allowed: inputs are mapped there (read over the bus).
  const std::uint32_t systemOnly = (1u << 3) | (1u << 4);
  expectPlacement(chooseMemory(m, systemOnly, MemoryUse::DeviceInput), 3, true, false);
  expectPlacement(chooseMemory(m, systemOnly, MemoryUse::Host), 3, true, false);
  expectPlacement(chooseMemory(m, systemOnly, MemoryUse::DeviceOnly), 3, false, false);
  // Only video memory the host cannot see: no host-visible placement at all.
  const std::uint32_t videoOnly = (1u << 1) | (1u << 2);
  EXPECT_FALSE(chooseMemory(m, videoOnly, MemoryUse::Host).has_value());
  expectPlacement(chooseMemory(m, videoOnly, MemoryUse::DeviceInput), 1, false, true);
  // No type at all.
  EXPECT_FALSE(chooseMemory(lavapipe(), 0u, MemoryUse::DeviceInput).has_value());
  EXPECT_FALSE(chooseMemory(lavapipe(), 0u, MemoryUse::DeviceOnly).has_value());
}

}  // namespace
}  // namespace haarcast::gpu
