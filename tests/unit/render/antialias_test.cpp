// Antialiasing on the CPU backend (shared_layout.h): interior pixels keep
// their one centre sample; an edge pixel is the mean of its four
// sub-samples, which are the pixel centres of the same frame at twice the
// resolution.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "haarcast/core/shared_layout.h"
#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/render/renderer.h"

namespace haarcast::render {
namespace {

RenderOptions options(int size, bool antialias) {
  RenderOptions o;
  o.width = o.height = size;
  o.level = 4;
  o.antialias = antialias;
  return o;
}

FrameRequest requestFor(const Scene& scene, int size) {
  FrameRequest r;
  r.width = r.height = size;
  r.camera = scene.camera;
  return r;
}

// True where the 3×3 neighbourhood of centre samples is not one object.
std::vector<bool> edgePixels(const Frame& plain) {
  const int w = plain.width, h = plain.height;
  std::vector<bool> edge(plain.objectMask.size(), false);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = std::clamp(x + dx, 0, w - 1), ny = std::clamp(y + dy, 0, h - 1);
          if (plain.objectMask[static_cast<std::size_t>(ny * w + nx)] != plain.objectMask[static_cast<std::size_t>(y * w + x)])
            edge[static_cast<std::size_t>(y * w + x)] = true;
        }
  return edge;
}

TEST(Antialias, EdgePixelsAreTheMeanOfTheDoubleResolutionFrame) {
  // The default scene's two objects do not touch, so "which object" changes
  // only where coverage does: edgePixels() finds the renderer's edge pixels.
  // (Its ground touches both, so it is left out here.)
  Scene scene = defaultScene();
  ASSERT_TRUE(scene.objects.back().ground);
  scene.objects.pop_back();
  const int n = 48;
  const auto aa = makeCpuRenderer(scene, options(n, true));
  const auto plain = makeCpuRenderer(scene, options(n, false));
  const auto twice = makeCpuRenderer(scene, options(2 * n, false));
  const Frame a = aa->render(requestFor(scene, n));
  const Frame p = plain->render(requestFor(scene, n));
  const Frame t = twice->render(requestFor(scene, 2 * n));
  const std::vector<bool> edge = edgePixels(p);
  std::size_t edges = 0, changed = 0, agree = 0;
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const std::size_t i = static_cast<std::size_t>(y * n + x);
      for (int c = 0; c < 3; ++c) {
        const float av = a.image.at(y, x, c);
        if (!edge[i]) {
          ASSERT_EQ(av, p.image.at(y, x, c)) << "interior pixel " << x << "," << y << " changed";
          continue;
        }
        changed += av != p.image.at(y, x, c);
      }
      if (!edge[i]) continue;
      ++edges;
      // Sub-sample k of (x, y) is pixel (2x + (k & 1), 2y + (k >> 1)) at 2n.
      bool same = true;
      for (int c = 0; c < 3; ++c) {
        double mean = 0.0;
        for (unsigned k = 0; k < shared::kSubsamples; ++k)
          mean += t.image.at(2 * y + static_cast<int>(k >> 1), 2 * x + static_cast<int>(k & 1u), c);
        mean /= shared::kSubsamples;
        same = same && std::abs(a.image.at(y, x, c) - mean) <= 1e-4 * (1.0 + std::abs(mean));
      }
      agree += same;
    }
  }
  EXPECT_GT(edges, 50u);
  EXPECT_GT(changed, edges / 2) << "antialiasing changed almost no edge pixel";
  // Rays through the same point may round differently at a triangle's edge.
  EXPECT_GE(agree, edges - edges / 50) << agree << " of " << edges << " edge pixels equal the 2×2 mean";
  EXPECT_EQ(a.objectMask, p.objectMask) << "the mask stays the centre samples'";
}

TEST(Antialias, ReportsTheSameStagesAndCountsTheSubsamplesBytes) {
  const Scene scene = defaultScene();
  const Frame a = makeCpuRenderer(scene, options(32, true))->render(requestFor(scene, 32));
  const Frame p = makeCpuRenderer(scene, options(32, false))->render(requestFor(scene, 32));
  ASSERT_EQ(a.stages.size(), p.stages.size());
  for (std::size_t i = 0; i < a.stages.size(); ++i) EXPECT_EQ(a.stages[i].name, p.stages[i].name);
  EXPECT_GT(a.coefficientBytes, p.coefficientBytes) << "the edge sub-samples read coefficients too";
}

}  // namespace
}  // namespace haarcast::render
