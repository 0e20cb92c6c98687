// The CPU reference backend: the seed's passes on the CPU, one definition of
// every number that the Vulkan backend is tested against.
//
//   once per object   slice tables (unrotated, cached on disk), a rotator per
//                     channel, per-vertex visibility in the object frame
//   once per frame    the light rotated world→object, solid angle folded in,
//                     Haar-coded and cut to its k largest coefficients
//   per pixel         G-buffer by Embree primary rays → slice index (θₒ) and
//                     Y-X-Y Euler angles of the local frame → rotation of the
//                     slice by the chosen method → triple product with the
//                     light and the barycentric blend of the three vertices'
//                     visibility (linear, so three triple products)
//
// Visibility is each object's own (self-shadowing); objects do not shadow
// each other, as in precomputed-transfer renderers whose objects move.
#pragma once

#include <cstddef>
#include <functional>
#include <string>

#include "haarcast/core/rotation.h"
#include "haarcast/io/image.h"
#include "haarcast/render/scene.h"
#include "haarcast/render/visibility.h"

namespace haarcast::render {

struct RenderOptions {
  int width = 128;
  int height = 128;
  int level = 5;                          // map level of light, slices and visibility
  RotationMethod method = kDefaultPixelMethod;
  // fused: blend the two nearest θₒ slices (false: the nearest alone, as the
  // rotating methods do).
  bool interpolateSlices = true;
  RotatorOptions rotator;
  std::size_t lightCoefficients = 256;    // k: the light's largest coefficients kept
  int thetaSamples = 16;                  // BRDF slices per channel
  int sliceSupersampling = 4;
  VisibilityOptions visibility;           // its level is overridden by `level`
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
