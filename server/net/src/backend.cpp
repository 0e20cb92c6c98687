#include "haarcast/net/backend.h"

#include <stdexcept>

// The Vulkan backend arrives with step 3; until its header exists this file
// builds with the CPU backend alone, and `vulkan` is reported as not built in.
#if __has_include("haarcast/gpu/vulkan_renderer.h")
#include "haarcast/gpu/vulkan_renderer.h"
#define HAARCAST_HAVE_VULKAN 1
#else
#define HAARCAST_HAVE_VULKAN 0
#endif

namespace haarcast::net {

std::vector<std::string> availableBackends() {
  std::vector<std::string> b{"cpu"};
  if (HAARCAST_HAVE_VULKAN) b.emplace_back("vulkan");
  return b;
}

std::unique_ptr<render::Renderer> makeRenderer(std::string_view backend, const render::Scene& scene,
                                               const render::RenderOptions& options,
                                               [[maybe_unused]] const BackendOptions& backendOptions,
                                               const render::RenderProgress& progress) {
  if (backend == "cpu") return render::makeCpuRenderer(scene, options, progress);
  if (backend == "vulkan") {
#if HAARCAST_HAVE_VULKAN
    return gpu::makeVulkanRenderer(scene, options,
                                   gpu::VulkanOptions{backendOptions.vulkanDevice, backendOptions.vulkanValidation},
                                   progress);
#else
    throw std::invalid_argument("backend \"vulkan\" is not built into this server (cpu only)");
#endif
  }
  throw std::invalid_argument("unknown backend \"" + std::string(backend) + "\" (cpu or vulkan)");
}

}  // namespace haarcast::net
