// The renderer backends' names, defined once: the command line (--backend),
// the protocol (RenderSettings.backend), the logs and the reports say these.
// Which of them a build has, and the factory that makes a renderer by name,
// are haarcast/backends/backends.h.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string_view>

namespace haarcast::render {

inline constexpr std::string_view kCpuBackend = "cpu";        // server/cpu: the CPU backend (cpu_renderer.h)
inline constexpr std::string_view kVulkanBackend = "vulkan";  // server/gpu: Vulkan compute (vulkan_renderer.h)
// Every backend haarcast knows, in the order they are listed to people.
inline constexpr std::array<std::string_view, 2> kBackendNames = {kCpuBackend, kVulkanBackend};
// Where a frame's shadow rays are traced (--rays; the Vulkan backend's
// choice, gpu::VulkanRendererLimits::rays): `device` in a ray-tracing
// pipeline on the GPU (gpu/ray_tracing.h), `host` by Embree between the
// frame's two submissions, `auto` the device where it traces rays and is a
// GPU (on lavapipe, Embree on the same cores is faster: docs/gpu.md). The
// CPU backend's rays are always the host's.
enum class RayMode { Auto, Device, Host };
inline constexpr std::array<std::string_view, 3> kRayModeNames = {"auto", "device", "host"};
inline constexpr std::string_view rayModeName(RayMode mode) { return kRayModeNames[static_cast<std::size_t>(mode)]; }
inline constexpr std::optional<RayMode> parseRayMode(std::string_view name) {
  for (std::size_t i = 0; i < kRayModeNames.size(); ++i)
    if (kRayModeNames[i] == name) return static_cast<RayMode>(i);
  return std::nullopt;
}

// A device backend's validation layer by default: on in debug builds (tests
// turn it on always). backends::DeviceOptions and gpu::VulkanOptions start here.
#ifdef NDEBUG
inline constexpr bool kValidationByDefault = false;
#else
inline constexpr bool kValidationByDefault = true;
#endif

}  // namespace haarcast::render
