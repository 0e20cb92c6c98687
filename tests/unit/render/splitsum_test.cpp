// `splitsum` on the CPU backend: what prepareScene keeps for it, and a
// frame under a uniform sky, where every pixel is its lobe's energy.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <limits>

#include "haarcast/assets/procedural_mesh.h"
#include "haarcast/core/lobe.h"
#include "haarcast/core/splitsum.h"
#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/render/renderer.h"

namespace haarcast::render {
namespace {

Scene ballScene(const Environment& environment, const std::string& material) {
  Scene s;
  s.environment = environment;
  s.objects.push_back({"ball", std::make_shared<Mesh>(assets::makeSphere(32)), materialFromSpec(material), {}});
  s.camera.eye = {0.0, 0.0, 3.0};
  s.camera.fovYDegrees = 42.0;
  return s;
}

RenderOptions splitsumOptions() {
  RenderOptions o;
  o.method = RotationMethod::Splitsum;
  o.width = o.height = 48;
  o.level = 4;
  o.thetaSamples = 8;
  o.environmentBackground = false;
  return o;
}

TEST(Splitsum, PreparesItsLobesAndThePrefilteredLightAndNothingElse) {
  const PreparedScene p = prepareScene(ballScene(builtinEnvironment(), "ggx:0.1"), splitsumOptions());
  ASSERT_EQ(p.objects.size(), 1u);
  EXPECT_EQ(p.objects[0].table.thetaSamples(), 0) << "no slice table";
  EXPECT_TRUE(p.objects[0].visibility.empty());
  EXPECT_EQ(p.objects[0].visibilityBits.pointCount(), 0u);
  EXPECT_EQ(p.objects[0].lobes.size(), 8u);
  EXPECT_TRUE(p.objects[0].lobePath);
  EXPECT_EQ(p.lobeLight.finestLevel(), kBackgroundLevel);
}

TEST(Splitsum, UnderAUniformSkyEveryPixelIsItsLobesEnergy) {
  // L = 1 and nothing else in the scene: each pixel is E_c(θₒ) blended
  // between the θₒ samples, so it lies between the lobes' least and
  // greatest energy; the pixel facing the camera (θₒ below the first
  // sample) is exactly the first lobe's. At the silhouette a grazing mirror
  // ray may meet the tessellated ball's next facet (its shading normal is
  // not its facets'): such a pixel is black, as one ray says.
  const std::string material = "ggx:0.3";
  const RenderOptions o = splitsumOptions();
  const Scene scene = ballScene(constantEnvironment(1.0), material);
  const auto renderer = makeCpuRenderer(scene, o);
  FrameRequest request;
  request.width = o.width;
  request.height = o.height;
  request.camera = scene.camera;
  const Frame frame = renderer->render(request);
  const std::vector<shared::SliceLobe> lobes = measureLobes(*scene.objects[0].material.brdf, lobeThetaOut(o.thetaSamples));
  std::array<float, 3> lo, hi;
  lo.fill(std::numeric_limits<float>::max());
  hi.fill(0.0f);
  for (const shared::SliceLobe& l : lobes)
    for (int c = 0; c < 3; ++c) {
      lo[static_cast<std::size_t>(c)] = std::min(lo[static_cast<std::size_t>(c)], l.energy[c]);
      hi[static_cast<std::size_t>(c)] = std::max(hi[static_cast<std::size_t>(c)], l.energy[c]);
    }
  auto covers = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < o.width && y < o.height && frame.objectMask[static_cast<std::size_t>(y * o.width + x)];
  };
  std::size_t covered = 0, blocked = 0;
  for (int y = 0; y < o.height; ++y)
    for (int x = 0; x < o.width; ++x) {
      if (!covers(x, y)) continue;
      ++covered;
      bool silhouette = false;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) silhouette = silhouette || !covers(x + dx, y + dy);
      if (silhouette && frame.image.at(y, x, 0) == 0.0f) {
        ++blocked;
        continue;
      }
      for (int c = 0; c < 3; ++c) {
        const float v = frame.image.at(y, x, c);
        EXPECT_GE(v, lo[static_cast<std::size_t>(c)] * (1.0f - 1e-6f)) << x << ", " << y << " channel " << c;
        EXPECT_LE(v, hi[static_cast<std::size_t>(c)] * (1.0f + 1e-6f)) << x << ", " << y << " channel " << c;
      }
    }
  EXPECT_GT(covered, 600u);
  EXPECT_LE(blocked, 8u);
  for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(frame.image.at(o.height / 2, o.width / 2, c), lobes[0].energy[c]) << c;
  ASSERT_FALSE(frame.stages.empty());
  EXPECT_EQ(frame.stages[3].name, "splitsum");
  EXPECT_EQ(frame.coefficientBytes, covered * splitsumPixelBytes());
}

}  // namespace
}  // namespace haarcast::render
