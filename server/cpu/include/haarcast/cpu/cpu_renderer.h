// The CPU reference backend: the seed's passes on the CPU, one definition of
// every number that the Vulkan backend is tested against.
//
//   once per object   slice tables (unrotated, cached on disk), per-vertex
//                     visibility in the object frame; for `fused` the slices
//                     in pixel form, for the rotating methods their rotators
//   once per frame    resolveFrame: the light rotated world→object, solid
//                     angle folded in, Haar-coded, cut to its k largest
//                     coefficients (for `fused` synthesised to pixel form)
//   per pixel         G-buffer by Embree primary rays → θₒ and the Y-X-Y
//                     Euler angles of the local frame → the three vertices'
//                     visibility merged with their barycentric weights (the
//                     product is linear in V) → `fused`: one pass over the map
//                     directions (core/fused.h); the rotating methods: the
//                     slice rotated (the three channels together for haar),
//                     then one triple product per channel
//
// Per-vertex visibility is each object's own (self-shadowing). `fused` adds
// per-pixel shadow rays toward the light's point lights against the whole
// posed scene, so objects shadow each other and the ground from those
// (docs/design.md, "Visibility in `fused`"); the Haar methods keep the
// seed's self-shadowing only.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <string>

#include "haarcast/io/image.h"
#include "haarcast/render/render_options.h"
#include "haarcast/render/renderer.h"
#include "haarcast/render/scene.h"

namespace haarcast::render {

struct RenderTimings {
  double precompute = 0.0;  // slice tables, rotators, visibility
  double light = 0.0;       // light to object frames
  double gbuffer = 0.0;
  double shading = 0.0;     // rotation + triple product
};

struct RenderResult {
  io::RgbImage image;       // linear radiance
  std::vector<std::uint8_t> objectMask;  // 1 where an object was hit
  RenderTimings timings;
};

RenderResult renderCpu(const Scene& scene, const RenderOptions& options, const RenderProgress& progress = {});

// The CPU backend behind the renderer interface (render/renderer.h). The
// scene is copied; precomputation (slice tables, rotators, visibility)
// happens here.
std::unique_ptr<Renderer> makeCpuRenderer(const Scene& scene, const RenderOptions& options,
                                          const RenderProgress& progress = {});

}  // namespace haarcast::render
