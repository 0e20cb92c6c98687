#include "haarcast/backends/backends.h"

#include <algorithm>
#include <stdexcept>

#include "haarcast/cpu/cpu_renderer.h"
#if HAARCAST_HAS_VULKAN
#include "haarcast/gpu/context.h"
#include "haarcast/gpu/engine.h"
#include "haarcast/gpu/vulkan_renderer.h"
#endif

namespace haarcast::backends {

bool built(std::string_view name) {
  if (name == render::kCpuBackend) return true;
  if (name == render::kVulkanBackend) return HAARCAST_HAS_VULKAN != 0;
  return false;
}

std::vector<std::string> available() {
  std::vector<std::string> names;
  for (const std::string_view name : render::kBackendNames)
    if (built(name)) names.emplace_back(name);
  return names;
}

std::string availableText() {
  std::string text;
  for (const std::string& name : available()) text += (text.empty() ? "" : ", ") + name;
  return text;
}

std::string buildDescription() {
  std::string text = "backends in this build: " + availableText();
  if (!built(render::kVulkanBackend)) text += " (built without Vulkan: configure with -DHAARCAST_VULKAN=ON for the vulkan backend)";
  return text;
}

void checkBuilt(std::string_view name, std::string_view what) {
  if (built(name)) return;
  const bool known = std::find(render::kBackendNames.begin(), render::kBackendNames.end(), name) != render::kBackendNames.end();
  if (known) {
    throw std::invalid_argument(std::string(what) + " " + std::string(name) +
                                ": this build has no such backend (it was configured with -DHAARCAST_VULKAN=OFF); " +
                                "backends in this build: " + availableText());
  }
  throw std::invalid_argument(std::string(what) + " \"" + std::string(name) + "\" is not a backend (valid: " + availableText() + ")");
}

std::unique_ptr<render::Renderer> makeRenderer(std::string_view backend, const render::Scene& scene,
                                               const render::RenderOptions& options, const DeviceOptions& device,
                                               const render::RenderProgress& progress) {
  checkBuilt(backend);
  if (backend == render::kCpuBackend) return render::makeCpuRenderer(scene, options, progress);
#if HAARCAST_HAS_VULKAN
  gpu::VulkanOptions vulkan;
  vulkan.device = device.device;
  vulkan.validation = device.validation;
  vulkan.queues = device.queues;
  gpu::VulkanRendererLimits limits;
  limits.framesInFlight = device.framesInFlight;
  limits.fusedLocalSize = device.fusedLocalSize;
  limits.rays = device.rays;
  return gpu::makeVulkanRenderer(scene, options, vulkan, progress, limits);
#else
  static_cast<void>(device);
  throw std::logic_error("backend " + std::string(backend) + " passed checkBuilt but has no factory");
#endif
}

std::vector<DeviceSummary> vulkanDevices(bool validation) {
  std::vector<DeviceSummary> out;
#if HAARCAST_HAS_VULKAN
  for (const gpu::DeviceInfo& d : gpu::Engine::get(gpu::EngineOptions{validation}).devices())
    out.push_back({d.index, d.name, d.type, d.apiVersionText, d.rejected});
#else
  static_cast<void>(validation);
#endif
  return out;
}

}  // namespace haarcast::backends
