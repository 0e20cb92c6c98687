// The backend registry: which renderer backends this build has, and the one
// factory that makes a renderer by name (render --backend, bench-frame
// --backend, serve --backend and a session's RenderSettings.backend all come
// here). It sits above server/cpu and server/gpu, which know nothing of each
// other: a build configured with -DHAARCAST_VULKAN=OFF has the CPU backend
// alone, and asking it for "vulkan" is an error that says so.
//
// The names themselves are render/backend_names.h.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "haarcast/render/backend_names.h"
#include "haarcast/render/renderer.h"
#include "haarcast/render/scene.h"

namespace haarcast::backends {

// Validation layers by default in debug builds (render/backend_names.h).
inline constexpr bool kValidationByDefault = render::kValidationByDefault;

// Which device a device backend (Vulkan) runs on; the CPU backend has none.
struct DeviceOptions {
  // A device index (as listDevices numbers them) or a case-insensitive
  // substring of its name; empty = the backend's automatic choice.
  std::string device;
  // The Vulkan validation layer, when installed.
  bool validation = kValidationByDefault;
  // Vulkan: frames one renderer may have in flight at once
  // (gpu::VulkanRendererLimits::framesInFlight; 0 = 1 on a CPU device, 2 on a GPU).
  std::size_t framesInFlight = 0;
  // Vulkan: where the shadow rays are traced (render/backend_names.h,
  // gpu::VulkanRendererLimits::rays).
  render::RayMode rays = render::RayMode::Auto;
  // Vulkan: the most queues the device is opened with (gpu::VulkanOptions::queues;
  // 0 = all its family offers, at most 16); the first renderer on it decides.
  std::uint32_t queues = 1;
  // Vulkan: `fused`'s workgroup size (gpu::VulkanRendererLimits::fusedLocalSize;
  // 0 = the device's default).
  std::uint32_t fusedLocalSize = 0;
};

// True when this build has `name` (one of render::kBackendNames).
bool built(std::string_view name);
// The backends this build has, in render::kBackendNames' order.
std::vector<std::string> available();
// "cpu, vulkan" (or "cpu" alone): for messages and --help.
std::string availableText();
// What --help says about the build: "backends in this build: cpu, vulkan",
// or, without Vulkan, how to get it.
std::string buildDescription();
// Throws std::invalid_argument naming the problem: a name haarcast does not
// know (with the known ones), or one this build lacks (and why). `what` is
// how the message names the value, e.g. "--backend".
void checkBuilt(std::string_view name, std::string_view what = "backend");

// A renderer of `backend` for the scene: "cpu" or "vulkan". Throws as
// checkBuilt; whatever the backend throws while preparing passes through.
std::unique_ptr<render::Renderer> makeRenderer(std::string_view backend, const render::Scene& scene,
                                               const render::RenderOptions& options, const DeviceOptions& device = {},
                                               const render::RenderProgress& progress = {});

// A physical device a device backend could run on.
struct DeviceSummary {
  int index = 0;
  std::string name, type, api;
  std::string rejected;  // empty when usable, else why not
};
// The Vulkan devices (empty in a build without Vulkan). The first Vulkan
// use in the process makes its one engine (gpu/engine.h), with the
// validation layer as `validation` asks; later calls list the same devices.
// Throws when the Vulkan loader cannot list them.
std::vector<DeviceSummary> vulkanDevices(bool validation = kValidationByDefault);

}  // namespace haarcast::backends
