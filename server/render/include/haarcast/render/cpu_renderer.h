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
#include <string>

#include "haarcast/core/light_split.h"
#include "haarcast/core/rotation.h"
#include "haarcast/io/image.h"
#include "haarcast/render/scene.h"
#include "haarcast/render/visibility.h"
#include "haarcast/render/visibility_refine.h"

namespace haarcast::render {

struct RenderOptions {
  int width = 128;
  int height = 128;
  // Map level of light, slices and visibility: every object's, or with
  // automaticLevel the cap of `fused`'s levels per object.
  int level = 5;
  // `fused` only: each object at its own level, the smallest at which its
  // material's lobe spans enough texels (core/lobe.h chooseLevel), within
  // [kAutoLevelFloor, level] (render/object_levels.h). Off here, so that
  // measurements and tests keep one level; `render` and `serve` turn it on.
  // The other methods keep `level` for every object.
  bool automaticLevel = false;
  RotationMethod method = kDefaultPixelMethod;
  // fused: blend the two nearest θₒ slices (false: the nearest alone, as the
  // rotating methods do).
  bool interpolateSlices = true;
  // Edge pixels drawn as the mean of shared::kSubsamples sub-samples
  // (shared_layout.h); interior pixels keep one sample at the centre. Off
  // here, so that measurements compare one sample per pixel with the
  // reference; `render` and `serve` turn it on for what users look at.
  bool antialias = false;
  RotatorOptions rotator;
  std::size_t lightCoefficients = 256;    // k: the light's largest coefficients kept
  int thetaSamples = 16;                  // BRDF slices per channel
  int sliceSupersampling = 4;
  VisibilityOptions visibility;           // its level is overridden by each object's
  // fused: the light's brightest regions taken out as point lights with a
  // shadow ray per pixel each (core/light_split.h); maxLights 0 = none,
  // at most shared::kMaxPointLights.
  LightSplitOptions pointLights;
  RefineOptions refine;                   // fused: the mesh refined where visibility changes (visibility_refine.h)
  SceneLimits sceneLimits;                // objects, triangles, visibility memory (prepareScene)
  bool environmentBackground = true;      // false: black where no object is
  std::string cacheDir;                   // slice-table and visibility cache; empty = none
  unsigned threads = 0;                   // 0 = hardware concurrency
};

// Throws std::invalid_argument naming the bad option (sizes over 8192², level
// outside 2..8 — 2..7 for fused —, k = 0, …).
void checkRenderOptions(const RenderOptions& options);

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

// progress(stage, done, total) for long stages, on the calling thread; may be
// empty.
using RenderProgress = std::function<void(const std::string& stage, std::size_t done, std::size_t total)>;

RenderResult renderCpu(const Scene& scene, const RenderOptions& options, const RenderProgress& progress = {});

}  // namespace haarcast::render
