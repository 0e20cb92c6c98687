// The backend factory: `render --backend`, `bench-frame --backend`, `serve
// --backend` and a session's RenderSettings.backend pick a renderer by name
// here and nowhere else.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "haarcast/gpu/vulkan_renderer.h"
#include "haarcast/render/renderer.h"

namespace haarcast::gpu {

// The backends this build has, in order of preference for display: "cpu", "vulkan".
std::vector<std::string> availableBackends();

// "cpu" (the reference) or "vulkan" (`vulkan` says which device and whether
// validation is on). Throws std::invalid_argument naming an unknown backend;
// whatever the backend throws while preparing passes through.
std::unique_ptr<render::Renderer> makeRenderer(std::string_view backend, const render::Scene& scene,
                                               const render::RenderOptions& options, const VulkanOptions& vulkan = {},
                                               const render::RenderProgress& progress = {});

}  // namespace haarcast::gpu
