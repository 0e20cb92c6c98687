#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/gpu/backend.h"

#include <stdexcept>

namespace haarcast::gpu {

std::vector<std::string> availableBackends() { return {"cpu", "vulkan"}; }

std::unique_ptr<render::Renderer> makeRenderer(std::string_view backend, const render::Scene& scene,
                                               const render::RenderOptions& options, const VulkanOptions& vulkan,
                                               const render::RenderProgress& progress) {
  if (backend == "cpu") return render::makeCpuRenderer(scene, options, progress);
  if (backend == "vulkan") return makeVulkanRenderer(scene, options, vulkan, progress);
  throw std::invalid_argument("unknown backend \"" + std::string(backend) + "\" (cpu or vulkan)");
}

}  // namespace haarcast::gpu
