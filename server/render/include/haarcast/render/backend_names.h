// The renderer backends' names, defined once: the command line (--backend),
// the protocol (RenderSettings.backend), the logs and the reports say these.
// Which of them a build has, and the factory that makes a renderer by name,
// are haarcast/backends/backends.h.
#pragma once

#include <array>
#include <string_view>

namespace haarcast::render {

inline constexpr std::string_view kCpuBackend = "cpu";        // server/cpu: the CPU backend (cpu_renderer.h)
inline constexpr std::string_view kVulkanBackend = "vulkan";  // server/gpu: Vulkan compute (vulkan_renderer.h)
// Every backend haarcast knows, in the order they are listed to people.
inline constexpr std::array<std::string_view, 2> kBackendNames = {kCpuBackend, kVulkanBackend};
// A device backend's validation layer by default: on in debug builds (tests
// turn it on always). backends::DeviceOptions and gpu::VulkanOptions start here.
#ifdef NDEBUG
inline constexpr bool kValidationByDefault = false;
#else
inline constexpr bool kValidationByDefault = true;
#endif

}  // namespace haarcast::render
