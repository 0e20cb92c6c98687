// The CPU renderer against analytic answers.
#include "haarcast/cpu/cpu_renderer.h"

#include <gtest/gtest.h>

#include <cstdio>

#include "haarcast/assets/procedural_mesh.h"
#include "haarcast/render/renderer.h"

namespace haarcast::render {
namespace {

Scene sphereScene(const std::string& material, double light) {
  Scene s;
  s.environment = constantEnvironment(light);
  s.objects.push_back({"sphere", std::make_shared<Mesh>(assets::makeSphere(32)), materialFromSpec(material), {}});
  s.camera.eye = {0.0, 0.0, 3.0};
  return s;
}

RenderOptions smallOptions() {
  RenderOptions o;
  o.width = o.height = 24;
  o.level = 4;
  o.thetaSamples = 8;
  o.visibility.supersampling = 1;
  o.environmentBackground = false;
  o.lightCoefficients = 1u << 20;  // all
  return o;
}

TEST(CpuRenderer, LambertSphereUnderConstantLightIsAlbedoTimesLight) {
  // A convex object sees its whole upper hemisphere: L_o = ρ·L·∫cos/π = 0.8·L.
  const RenderResult r = renderCpu(sphereScene("lambert", 2.0), smallOptions());
  int hits = 0;
  for (int y = 0; y < r.image.height; ++y)
    for (int x = 0; x < r.image.width; ++x) {
      if (!r.objectMask[static_cast<std::size_t>(y * r.image.width + x)]) {
        EXPECT_EQ(r.image.at(y, x, 0), 0.0f);
        continue;
      }
      ++hits;
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.image.at(y, x, c), 1.6, 0.05) << x << "," << y;
    }
  EXPECT_GT(hits, 100);
}

TEST(CpuRenderer, EveryRotationMethodAgreesWithSpatialWhereTheyShould) {
  // haar (refined) reproduces spatial exactly; a render through either is the same image.
  RenderOptions o = smallOptions();
  const Scene scene = sphereScene("phong:32", 1.0);
  o.method = RotationMethod::Spatial;
  const RenderResult spatial = renderCpu(scene, o);
  o.method = RotationMethod::Haar;
  const RenderResult haar = renderCpu(scene, o);
  for (std::size_t i = 0; i < spatial.image.rgb.size(); ++i) EXPECT_NEAR(haar.image.rgb[i], spatial.image.rgb[i], 1e-4);
}

TEST(CpuRenderer, FusedEqualsSpatialRotationAndTheTripleProduct) {
  // Parseval: the pixel-basis sum of fused is the Haar-basis triple product
  // of the spatially rotated slice. With the nearest θₒ slice (as spatial
  // takes it), the light and the visibility whole (fused cuts neither; its
  // bits are one ray per pixel, as supersampling 1 makes the lists) the
  // frames agree up to fused's energy factor ∫ρ / Σ ΔΩ·ρ(Rᵀω) per pixel
  // (fused.h; the exact relation is checked pixel by pixel in
  // core/fused_test.cpp): for this lobe, about a level-4 texel wide, up to
  // 5 % of the peak at level 4 and 2 % at level 5, in the highlight. (At
  // level 3 the lobe is under half a texel and takes the lobe path.)
  const Scene scene = sphereScene("phong:32", 1.0);
  for (int level : {4, 5}) {
    RenderOptions o = smallOptions();
    o.level = level;
    o.visibility.keep = std::size_t{1} << (2 * level);
    o.method = RotationMethod::Spatial;
    const RenderResult spatial = renderCpu(scene, o);
    o.method = RotationMethod::Fused;
    o.interpolateSlices = false;
    const RenderResult fused = renderCpu(scene, o);
    ASSERT_EQ(fused.objectMask, spatial.objectMask);
    float peak = 0.0f;
    for (float v : spatial.image.rgb) peak = std::max(peak, v);
    ASSERT_GT(peak, 0.0f);
    double worst = 0.0;
    for (std::size_t i = 0; i < spatial.image.rgb.size(); ++i)
      worst = std::max(worst, double(std::abs(fused.image.rgb[i] - spatial.image.rgb[i])) / peak);
    std::printf("fused against spatial + triple product, level %d: max difference %.3g of the peak\n", level, worst);
    EXPECT_LT(worst, level == 4 ? 0.07 : 0.025) << "level " << level;
    // Blending neighbouring θₒ slices changes the picture a little, not a lot.
    o.interpolateSlices = true;
    const RenderResult blended = renderCpu(scene, o);
    double diff = 0.0;
    for (std::size_t i = 0; i < spatial.image.rgb.size(); ++i) diff = std::max(diff, double(std::abs(blended.image.rgb[i] - fused.image.rgb[i])));
    EXPECT_GT(diff, 1e-6 * peak);
    EXPECT_LT(diff, 0.25 * peak);
  }
}

TEST(CpuRenderer, MeshesWithoutNormalsGetThemComputed) {
  Scene scene = sphereScene("lambert", 1.0);
  auto bare = std::make_shared<Mesh>(*scene.objects[0].mesh);
  bare->normals.clear();
  scene.objects[0].mesh = bare;
  const RenderResult r = renderCpu(scene, smallOptions());
  const std::size_t centre = static_cast<std::size_t>(12 * r.image.width + 12);
  ASSERT_TRUE(r.objectMask[centre]);
  EXPECT_NEAR(r.image.at(12, 12, 0), 0.8, 0.05);  // faceted normals, same answer
}

TEST(CpuRenderer, BadOptionsAreRefusedByName) {
  RenderOptions o = smallOptions();
  o.width = 100000;
  EXPECT_THROW(checkRenderOptions(o), std::invalid_argument);
  o = smallOptions();
  o.level = 1;
  EXPECT_THROW(checkRenderOptions(o), std::invalid_argument);
  o = smallOptions();
  o.lightCoefficients = 0;
  EXPECT_THROW(checkRenderOptions(o), std::invalid_argument);
  o = smallOptions();
  o.method = RotationMethod::Fused;
  o.level = kMaxRenderLevel + 1;  // one range for every method
  EXPECT_THROW(checkRenderOptions(o), std::invalid_argument);
  o.method = RotationMethod::Haar;
  try {
    checkRenderOptions(o);
    ADD_FAILURE() << "level " << o.level << " accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("outside 2..7"), std::string::npos) << e.what();
  }
  o.level = kMaxRenderLevel;
  EXPECT_NO_THROW(checkRenderOptions(o));
  EXPECT_THROW(materialFromSpec("phong:"), std::invalid_argument);
  EXPECT_THROW(materialFromSpec("velvet"), std::invalid_argument);
}

}  // namespace
}  // namespace haarcast::render
