// Where a buffer's memory lives: a pure choice from the device's memory types
// and heaps (VkPhysicalDeviceMemoryProperties), testable without a device.
//
//   use           memory                                         host access
//   Host          host-visible + coherent, device-local too      mapped (written by the host)
//                 where a type offers both
//   Readback      host-visible + coherent + cached, preferring   mapped (read by the host)
//                 a type that is not device-local
//   DeviceInput   device-local                                   mapped where all of device-local memory is
//                                                                host-visible (CPU devices, integrated GPUs,
//                                                                resizable BAR); else staged: the host writes a
//                                                                staging buffer and a transfer copies it over
//   DeviceOnly    device-local, preferring a type the host        none
//                 cannot see (it does not use up a BAR window)
//
// "All of device-local memory": the host-visible device-local type sits on
// a heap as large as the largest device-local heap. A discrete GPU without
// resizable BAR offers such a type too, but only as a 256 MiB window onto
// its memory; inputs of hundreds of MiB do not belong there.
//
// Readback exists because the host reads device-local host-visible memory
// (a BAR window) uncached, one PCIe round trip per load: on an H200 with
// resizable BAR a 256² fused frame spent about 0.5 s reading its G-buffer
// ids and samples back that way (1.7 fps), where cached system memory
// reads at memory speed. The device writes it over the bus instead, once.
#pragma once

#include <cstdint>
#include <optional>

#include <vulkan/vulkan.h>

namespace haarcast::gpu {

enum class MemoryUse {
  Host,         // written by the host every frame: uniforms, per-object records, staging
  Readback,     // written by the device, read by the host: results, samples the host traces
  DeviceInput,  // large and read-only to the passes, written by the host (scene data, the light)
  DeviceOnly,   // written and read by the device alone (intermediates)
};

struct MemoryPlacement {
  std::uint32_t type = 0;  // memory type index
  bool mapped = false;     // host-visible and mapped: the host writes and reads it directly
  bool staged = false;     // DeviceInput that is not mapped: uploads go through a staging buffer
};

// The memory type for a buffer of `use` among the types allowed by
// `typeBits` (VkMemoryRequirements::memoryTypeBits). directInputs = false
// stages DeviceInput even where it could be mapped (the discrete-GPU path,
// run on any device by tests). Nothing when no allowed type fits.
std::optional<MemoryPlacement> chooseMemory(const VkPhysicalDeviceMemoryProperties& memory, std::uint32_t typeBits,
                                            MemoryUse use, bool directInputs = true);

}  // namespace haarcast::gpu
