#include "haarcast/gpu/memory.h"

#include <algorithm>

namespace haarcast::gpu {
namespace {

constexpr VkMemoryPropertyFlags kHostShared = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
constexpr VkMemoryPropertyFlags kDeviceLocal = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;

// The first allowed type with every flag of `want` and none of `avoid`.
std::optional<std::uint32_t> firstType(const VkPhysicalDeviceMemoryProperties& memory, std::uint32_t typeBits,
                                       VkMemoryPropertyFlags want, VkMemoryPropertyFlags avoid = 0) {
  for (std::uint32_t i = 0; i < memory.memoryTypeCount && i < VK_MAX_MEMORY_TYPES; ++i) {
    const VkMemoryPropertyFlags flags = memory.memoryTypes[i].propertyFlags;
    if ((typeBits & (1u << i)) && (flags & want) == want && (flags & avoid) == 0) return i;
  }
  return std::nullopt;
}

// The size of the largest device-local heap (0 when there is none).
VkDeviceSize largestDeviceLocalHeap(const VkPhysicalDeviceMemoryProperties& memory) {
  VkDeviceSize largest = 0;
  for (std::uint32_t h = 0; h < memory.memoryHeapCount && h < VK_MAX_MEMORY_HEAPS; ++h) {
    if (memory.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) largest = std::max(largest, memory.memoryHeaps[h].size);
  }
  return largest;
}

// A host-visible, coherent, device-local type on a heap as large as the
// largest device-local heap: the host sees all of device-local memory.
std::optional<std::uint32_t> wholeDeviceMemoryMapped(const VkPhysicalDeviceMemoryProperties& memory,
                                                     std::uint32_t typeBits) {
  const VkDeviceSize largest = largestDeviceLocalHeap(memory);
  for (std::uint32_t i = 0; i < memory.memoryTypeCount && i < VK_MAX_MEMORY_TYPES; ++i) {
    const VkMemoryType& t = memory.memoryTypes[i];
    if ((typeBits & (1u << i)) && (t.propertyFlags & (kHostShared | kDeviceLocal)) == (kHostShared | kDeviceLocal) &&
        t.heapIndex < memory.memoryHeapCount && memory.memoryHeaps[t.heapIndex].size >= largest) {
      return i;
    }
  }
  return std::nullopt;
}

}  // namespace

std::optional<MemoryPlacement> chooseMemory(const VkPhysicalDeviceMemoryProperties& memory, std::uint32_t typeBits,
                                            MemoryUse use, bool directInputs) {
  switch (use) {
    case MemoryUse::Host: {
      auto type = firstType(memory, typeBits, kHostShared | kDeviceLocal);
      if (!type) type = firstType(memory, typeBits, kHostShared);
      if (!type) return std::nullopt;
      return MemoryPlacement{*type, true, false};
    }
    case MemoryUse::Readback: {
      constexpr VkMemoryPropertyFlags kCached = kHostShared | VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
      auto type = firstType(memory, typeBits, kCached, kDeviceLocal);
      if (!type) type = firstType(memory, typeBits, kCached);
      if (!type) type = firstType(memory, typeBits, kHostShared, kDeviceLocal);
      if (!type) type = firstType(memory, typeBits, kHostShared);
      if (!type) return std::nullopt;
      return MemoryPlacement{*type, true, false};
    }
    case MemoryUse::DeviceInput: {
      if (directInputs) {
        if (const auto type = wholeDeviceMemoryMapped(memory, typeBits)) return MemoryPlacement{*type, true, false};
      }
      if (const auto type = firstType(memory, typeBits, kDeviceLocal)) return MemoryPlacement{*type, false, true};
      // No device-local type allowed: host memory the device reads over the bus.
      if (const auto type = firstType(memory, typeBits, kHostShared)) return MemoryPlacement{*type, true, false};
      return std::nullopt;
    }
    case MemoryUse::DeviceOnly: {
      auto type = firstType(memory, typeBits, kDeviceLocal, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT);
      if (!type) type = firstType(memory, typeBits, kDeviceLocal);
      if (!type) type = firstType(memory, typeBits, 0);
      if (!type) return std::nullopt;
      return MemoryPlacement{*type, false, false};
    }
  }
  return std::nullopt;
}

}  // namespace haarcast::gpu
