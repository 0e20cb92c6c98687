// What a renderer is asked to be, for every backend: the options, the
// bounds every frame and option must keep (one set for the backends, the
// service and the clients), and the progress callback of long preparation.
#pragma once

#include <cstddef>
#include <functional>
#include <string>

#include "haarcast/core/light_split.h"
#include "haarcast/core/rotation.h"
#include "haarcast/core/shared_layout.h"
#include "haarcast/render/scene.h"
#include "haarcast/render/visibility.h"
#include "haarcast/render/visibility_refine.h"

namespace haarcast::render {

// The bounds a frame request must keep (checkFrameRequest), one set for every
// backend, the service and the clients.
inline constexpr int kMaxFrameSide = 8192;
// Map levels every per-pixel method accepts on both backends (`fused`'s cap).
inline constexpr int kMinRenderLevel = static_cast<int>(shared::kMinLevel);
inline constexpr int kMaxRenderLevel = static_cast<int>(shared::kFusedMaxLevel);
inline constexpr double kMinFovDegrees = 1.0;
inline constexpr double kMaxFovDegrees = 170.0;
inline constexpr double kMinEyeDistance = 1e-3;  // eye to target, scene units
inline constexpr double kMaxEyeDistance = 1e4;

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
  // fused, two objects or more besides a ground: each hides sky from the
  // others (point_lights.h objectSkyHidden); false: each object's map part
  // meets its own visibility alone.
  bool objectSky = true;
  // fused: the sum by cells' tolerance τ (core/shared_cells.h): at level
  // ≥ 5 a cell of 4 × 4 directions where the slice's detail is at most τ
  // is summed at one direction; 0 sums every direction. `render`, `serve`
  // and `bench-frame` take shared::kDefaultSumTolerance.
  float sumTolerance = 0.0f;
  // `fused`: ε > 0 takes a pixel's sum (the light's rest × V × ρ) from its
  // neighbours where theirs agree within ε of what they show
  // (core/shared_smooth.h); 0 sums every pixel. `render`, `serve` and
  // `bench-frame` take shared::kDefaultSmoothSumTolerance.
  float smoothSumTolerance = 0.0f;
  SceneLimits sceneLimits;                // objects, triangles, visibility memory (prepareScene)
  bool environmentBackground = true;      // false: black where no object is
  std::string cacheDir;                   // slice-table and visibility cache; empty = none
  unsigned threads = 0;                   // 0 = hardware concurrency
};

// Throws std::invalid_argument naming the bad option (a size outside
// 1..kMaxFrameSide, a level outside kMinRenderLevel..kMaxRenderLevel, k = 0, …).
void checkRenderOptions(const RenderOptions& options);

// progress(stage, done, total) for long stages, on the calling thread; may be
// empty.
using RenderProgress = std::function<void(const std::string& stage, std::size_t done, std::size_t total)>;

}  // namespace haarcast::render
