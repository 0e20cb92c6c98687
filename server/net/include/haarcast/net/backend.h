// The backend factory: `--backend cpu|vulkan` (and a session's
// RenderSettings.backend) pick a renderer by name here and nowhere else.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "haarcast/render/renderer.h"

namespace haarcast::net {

struct BackendOptions {
  std::string vulkanDevice;       // substring of the device name; empty = the first one
  bool vulkanValidation = false;  // Khronos validation layers
};

// Backends this build has: "cpu" always, "vulkan" when the GPU library is built in.
std::vector<std::string> availableBackends();

// Throws std::invalid_argument naming the backend when it is unknown or not
// built in; whatever the backend throws while preparing passes through.
std::unique_ptr<render::Renderer> makeRenderer(std::string_view backend, const render::Scene& scene,
                                               const render::RenderOptions& options, const BackendOptions& backendOptions,
                                               const render::RenderProgress& progress = {});

}  // namespace haarcast::net
