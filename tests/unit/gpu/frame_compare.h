// Whole-frame comparisons shared by the Vulkan renderer tests: the test
// cache, the default options and request, and the PSNR of one frame
// against a reference over the pixels both cover alike.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "haarcast/gpu/context.h"
#include "haarcast/render/renderer.h"

namespace haarcast::gpu::testing {

// One cache in the build tree for every test process (CTest runs each test
// in its own): slice tables and visibility are computed once and then read
// back. The cache writes atomically and checks what it reads, so parallel
// test processes may share it.
inline const std::string& cacheDir() {
  static const std::string path = HAARCAST_GPU_TEST_CACHE;
  return path;
}

// Vulkan fused vs CPU fused, whole frames (measured: see docs/gpu.md). On a
// CPU device (lavapipe) the G-buffer interpolates from unsnapped floats and
// frames differ by float rounding only: 127.7–135.5 dB measured. A hardware
// rasteriser snaps vertices to its sub-pixel grid first, which moves each
// pixel's shading point by up to ~1/256 px (GBufferPass): 88 dB measured on
// an H200, so there the floor is the project's Vulkan = CPU bar, 80 dB.
inline double fusedPsnrFloor(const Context& context) { return context.info().type == "cpu" ? 115.0 : 80.0; }

inline render::RenderOptions frameOptions(RotationMethod method, bool background) {
  render::RenderOptions o;
  o.width = o.height = 64;
  o.level = 4;
  o.method = method;
  o.environmentBackground = background;
  o.cacheDir = cacheDir();
  o.threads = 0;
  return o;
}

inline render::FrameRequest requestFor(const render::Scene& scene, int width, int height) {
  render::FrameRequest r;
  r.width = width;
  r.height = height;
  r.camera = scene.camera;
  // A fixed exposure, so that the device's tonemap pass makes the bytes
  // compared below (auto exposure has its own test).
  r.exposure.automatic = false;
  r.exposure.stops = -0.5;
  return r;
}

// Every object's pose in the scene (the default scene's ground included).
inline std::vector<render::Pose> scenePoses(const render::Scene& scene) {
  std::vector<render::Pose> poses;
  for (const render::SceneObject& o : scene.objects) poses.push_back(o.pose);
  return poses;
}

struct Comparison {
  double psnr = 0.0;
  double mse = 0.0;
  std::size_t compared = 0;       // pixels covered identically
  std::size_t objectPixels = 0;   // covered by either
  std::size_t mismatched = 0;     // covered by one only
};

// PSNR over the pixels both backends cover identically (object or
// background), peak = the reference's maximum over its object pixels
// (DESIGN.md "Measurements"); coverage mismatches counted separately.
inline Comparison compare(const render::Frame& reference, const render::Frame& test) {
  Comparison c;
  double peak = 0.0, sum = 0.0;
  const std::size_t pixels = reference.objectMask.size();
  for (std::size_t p = 0; p < pixels; ++p) {
    const bool a = reference.objectMask[p] != 0, b = test.objectMask[p] != 0;
    if (a || b) ++c.objectPixels;
    if (a != b) {
      ++c.mismatched;
      continue;
    }
    ++c.compared;
    for (std::size_t k = 0; k < 3; ++k) {
      const double r = reference.image.rgb[3 * p + k], t = test.image.rgb[3 * p + k];
      if (a) peak = std::max(peak, r);
      sum += (r - t) * (r - t);
    }
  }
  c.mse = c.compared ? sum / (3.0 * static_cast<double>(c.compared)) : 0.0;
  // A NaN anywhere makes the MSE NaN: that is the worst result, not a perfect one.
  c.psnr = std::isnan(c.mse)  ? -std::numeric_limits<double>::infinity()
           : c.mse > 0.0      ? 10.0 * std::log10(peak * peak / c.mse)
                              : std::numeric_limits<double>::infinity();
  return c;
}

}  // namespace haarcast::gpu::testing
