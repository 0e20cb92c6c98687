// The Renderer interface's CPU backend and the steps every backend shares.
#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/render/exposure_meter.h"
#include "haarcast/render/renderer.h"
#include "haarcast/render/shading.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "haarcast/assets/procedural_mesh.h"
#include "haarcast/io/image.h"

namespace haarcast::render {
namespace {

RenderOptions tinyOptions() {
  RenderOptions o;
  o.level = 4;
  o.thetaSamples = 4;
  o.sliceSupersampling = 2;
  o.visibility.supersampling = 1;
  o.lightCoefficients = 64;
  return o;
}

Scene torusScene() {
  Scene s;
  s.environment = builtinEnvironment();
  s.objects.push_back({"torus", std::make_shared<Mesh>(assets::makeTorus(0.6, 0.25, 24, 12)), materialFromSpec("phong:16"), {}});
  s.objects.front().pose.rotateDegrees = {50.0, 0.0, 0.0};
  s.camera.eye = {0.0, 0.3, 2.6};
  return s;
}

glm::dmat3 rotationAbout(const glm::dvec3& axis, double degrees) {
  return glm::dmat3(glm::rotate(glm::dmat4(1.0), glm::radians(degrees), axis));
}

TEST(SharedSteps, LightTurnedWithTheObjectLeavesTheObjectFrameLightUnchanged) {
  // L_obj(ω) = L(Rₗᵀ·R_obj·ω): the same R for both is the identity, exactly.
  const auto world = builtinEnvironment().maps(4);
  const glm::dmat3 r = rotationAbout(glm::normalize(glm::dvec3(0.3, 1.0, -0.2)), 37.0);
  // All coefficients kept: near-ties at the cut would otherwise swap on rounding.
  const auto still = lightInObjectFrame(world, glm::dmat3(1.0), glm::dmat3(1.0), 1u << 20);
  const auto turned = lightInObjectFrame(world, r, r, 1u << 20);
  for (std::size_t c = 0; c < 3; ++c) {
    const HaarMap a = still[c].toDense(), b = turned[c].toDense();
    float peak = 0.0f;
    for (float v : a.coefficients()) peak = std::max(peak, std::abs(v));
    for (std::size_t i = 0; i < a.coefficients().size(); ++i) EXPECT_NEAR(a.coefficients()[i], b.coefficients()[i], 1e-5f * peak);
  }
  // …and a light turn alone changes it.
  const auto lightOnly = lightInObjectFrame(world, glm::dmat3(1.0), r, 1u << 20);
  EXPECT_GT(std::abs(lightOnly[0].toDense().coefficients()[1] - still[0].toDense().coefficients()[1]), 1e-3f * std::abs(still[0].toDense().coefficients()[1]));
}

TEST(SharedSteps, LightTurnByWholePixelsAboutYIsAPermutationOfThePixels) {
  // Turning the world by 2 columns (level 4: 2·22.5°) about +Y moves the
  // object-frame light by whole pixels: its total is unchanged exactly.
  const auto world = builtinEnvironment().maps(4);
  const auto a = lightInObjectFrame(world, glm::dmat3(1.0), glm::dmat3(1.0), 1u << 20);
  const auto b = lightInObjectFrame(world, glm::dmat3(1.0), rotationAbout({0, 1, 0}, 45.0), 1u << 20);
  // The DC coefficient is the solid-angle-weighted sum / M: a pure φ-shift keeps it.
  EXPECT_NEAR(a[0].toDense().coefficients()[0], b[0].toDense().coefficients()[0], 1e-5 * std::abs(a[0].toDense().coefficients()[0]));
}

TEST(SharedSteps, BackgroundMatchesTheMapAtPixelCentresAndTurnsWithTheLight) {
  const auto maps = builtinEnvironment().maps(5);
  const int row = 9, col = 21;
  const glm::dvec3 d = sphericalToDirection(rowTheta(5, row), colPhi(5, col));
  const glm::vec3 L = backdropRadiance(maps, glm::mat3(1.0f), glm::vec3(d));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(L[c], maps[static_cast<std::size_t>(c)].at(row, col), 1e-5 * (1.0 + L[c]));
  // L'(ω) = L(Rᵀω): looking along R·d sees what d saw.
  const glm::dmat3 r = rotationAbout(glm::normalize(glm::dvec3(1.0, 0.5, 0.2)), 63.0);
  const glm::vec3 turned = backdropRadiance(maps, glm::mat3(glm::transpose(r)), glm::vec3(r * d));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(turned[c], L[c], 1e-4 * (1.0 + L[c]));
}

// The backdrop in double, from the maps' own bilinear taps (sphere_map.h).
glm::dvec3 backdropInDouble(const std::array<SphereMap, 3>& maps, const glm::dmat3& lightRotation, const glm::dvec3& direction) {
  const Spherical s = directionToSpherical(glm::transpose(lightRotation) * direction);
  const BilinearTaps taps = bilinearTaps(maps[0].level(), s.theta, s.phi);
  glm::dvec3 out(0.0);
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int c = 0; c < 3; ++c)
        out[c] += taps.weight(a, b) * maps[static_cast<std::size_t>(c)].at(taps.row[static_cast<std::size_t>(a)], taps.col[static_cast<std::size_t>(b)]);
  return out;
}

// The float backdrop a frame draws is the double lookup's, to float
// rounding, over directions everywhere on the sphere and a turned light.
TEST(SharedSteps, TheFloatBackdropIsTheDoubleOne) {
  const auto maps = builtinEnvironment().maps(7);
  const glm::dmat3 r = rotationAbout(glm::normalize(glm::dvec3(0.3, 1.0, -0.2)), 71.0);
  std::mt19937 rng(13);
  std::normal_distribution<double> g(0.0, 1.0);
  double worst = 0.0;
  for (int i = 0; i < 4000; ++i) {
    const glm::dvec3 d = glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
    const glm::dvec3 expected = backdropInDouble(maps, r, d);
    const glm::vec3 got = backdropRadiance(maps, glm::mat3(glm::transpose(r)), glm::vec3(d));
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(got[c] - expected[c]) / (1e-3 + std::abs(expected[c])));
  }
  EXPECT_LT(worst, 5e-4);  // 8e-5 measured (float's acos and atan2)
}

// The camera's field of view spans the frame's shorter side: a wide frame
// keeps it vertically, a tall one horizontally (and sees more vertically).
TEST(SharedSteps, TheFieldOfViewSpansTheShorterSide) {
  Camera camera;
  camera.fovYDegrees = 40.0;
  const double fov = glm::radians(camera.fovYDegrees);
  auto angle = [](const glm::dvec3& a, const glm::dvec3& b) { return std::acos(std::clamp(glm::dot(a, b), -1.0, 1.0)); };
  const CameraRays square(camera, 100, 100), wide(camera, 200, 100), tall(camera, 100, 200);
  EXPECT_NEAR(angle(square.directionAt(50, 0), square.directionAt(50, 100)), fov, 1e-9);
  EXPECT_NEAR(angle(square.directionAt(0, 50), square.directionAt(100, 50)), fov, 1e-9);
  EXPECT_NEAR(angle(wide.directionAt(100, 0), wide.directionAt(100, 100)), fov, 1e-9);
  EXPECT_NEAR(angle(tall.directionAt(0, 100), tall.directionAt(100, 100)), fov, 1e-9);
  EXPECT_GT(angle(tall.directionAt(50, 0), tall.directionAt(50, 200)), fov + 0.3);
  EXPECT_EQ(verticalTanHalf(camera, 100, 200), 2.0 * verticalTanHalf(camera, 100, 100));
}

TEST(SharedSteps, FrameRequestsAreCheckedWithClearErrors) {
  FrameRequest r;
  EXPECT_NO_THROW(checkFrameRequest(r, 2));
  r.width = 0;
  EXPECT_THROW(checkFrameRequest(r, 2), std::invalid_argument);
  r.width = 100000;
  try {
    checkFrameRequest(r, 2);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("100000"), std::string::npos);
  }
  r = FrameRequest{};
  r.poses.resize(3);
  EXPECT_THROW(checkFrameRequest(r, 2), std::invalid_argument);
  r = FrameRequest{};
  r.camera.target = r.camera.eye;
  EXPECT_THROW(checkFrameRequest(r, 2), std::invalid_argument);
  r = FrameRequest{};
  r.camera.fovYDegrees = 180.0;
  EXPECT_THROW(checkFrameRequest(r, 2), std::invalid_argument);
  r = FrameRequest{};
  r.camera.eye = r.camera.target + glm::dvec3(0.0, 0.0, 2.0 * kMaxEyeDistance);
  try {
    checkFrameRequest(r, 2);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("distance"), std::string::npos) << e.what();
  }
}

// Which objects fused sums by cells is decided once, in prepareScene, for
// both backends: not the ground (shaded in closed form), not a level below
// shared::kCellMinLevel, and not at all without a tolerance.
TEST(SharedSteps, TheSumByCellsIsEachObjectsTolerance) {
  Scene scene = torusScene();
  addGround(scene);
  RenderOptions o = tinyOptions();
  o.level = 5;
  o.sumTolerance = 0.1f;
  const PreparedScene atFive = prepareScene(scene, o);
  ASSERT_EQ(atFive.objects.size(), 2u);
  EXPECT_EQ(atFive.objects[0].sumTolerance, 0.1f);
  EXPECT_TRUE(atFive.objects[1].ground);
  EXPECT_EQ(atFive.objects[1].sumTolerance, 0.0f);
  o.level = 4;
  EXPECT_EQ(prepareScene(scene, o).objects[0].sumTolerance, 0.0f);
  o.level = 5;
  o.sumTolerance = 0.0f;
  EXPECT_EQ(prepareScene(scene, o).objects[0].sumTolerance, 0.0f);
}

TEST(CpuBackend, FramesAreRepeatableAndEqualTheOneShotRender) {
  const Scene scene = torusScene();
  RenderOptions o = tinyOptions();
  o.width = 32;
  o.height = 24;
  const auto renderer = makeCpuRenderer(scene, o);
  EXPECT_EQ(renderer->backend(), "cpu");
  EXPECT_EQ(renderer->objectCount(), 1u);
  FrameRequest request;
  request.width = 32;
  request.height = 24;
  request.camera = scene.camera;
  const Frame a = renderer->render(request);
  request.poses = {scene.objects.front().pose};  // the scene's own pose, given explicitly
  const Frame b = renderer->render(request);
  const RenderResult once = renderCpu(scene, o);
  ASSERT_EQ(a.image.rgb.size(), once.image.rgb.size());
  EXPECT_EQ(a.image.rgb, b.image.rgb);
  EXPECT_EQ(a.image.rgb, once.image.rgb);
  // Auto exposure by default, metered by exposure_meter.h.
  EXPECT_EQ(a.exposureStops, meterExposure(a.image, a.objectMask, {}, ToneCurve::Reinhard).stops);
  EXPECT_NE(a.exposureStops, 0.0);
  EXPECT_EQ(a.rgba8, tonemapRgba8(a.image, a.exposureStops));
  // Every stage is reported, in pipeline order (fused, the default, has one
  // pass where the rotating methods have two).
  const std::vector<std::string> names = {"light", "gbuffer", "rotation-input", "fused", "tonemap"};
  ASSERT_EQ(a.stages.size(), names.size());
  for (std::size_t i = 0; i < names.size(); ++i) EXPECT_EQ(a.stages[i].name, names[i]);
  EXPECT_GT(a.coefficientBytes, 0u);
  o.method = RotationMethod::Haar;
  const Frame rotating = makeCpuRenderer(scene, o)->render(request);
  const std::vector<std::string> rotatingNames = {"light", "gbuffer", "rotation-input", "rotation", "triple-product", "tonemap"};
  ASSERT_EQ(rotating.stages.size(), rotatingNames.size());
  for (std::size_t i = 0; i < rotatingNames.size(); ++i) EXPECT_EQ(rotating.stages[i].name, rotatingNames[i]);
}

// A renderer keeps each frame's G-buffer and per-sample records for the
// next (FrameLease): frames of other sizes and poses before, antialiased
// edges, a ground and two objects (every per-sample record fused keeps),
// must leave nothing behind.
TEST(CpuBackend, AFrameAfterOthersOfOtherSizesEqualsAFreshRenderersFrame) {
  Scene scene = torusScene();
  scene.objects.push_back({"sphere", std::make_shared<Mesh>(assets::makeSphere(16)), materialFromSpec("lambert"), {}});
  scene.objects.back().pose.translate = {0.9, 0.0, 0.0};
  scene.objects.back().pose.scale = 0.4;
  addGround(scene);
  RenderOptions o = tinyOptions();
  o.antialias = true;
  FrameRequest small;
  small.width = 20;
  small.height = 14;
  small.camera = scene.camera;
  FrameRequest large = small;
  large.width = 48;
  large.height = 36;
  large.poses = {scene.objects[0].pose, scene.objects[1].pose, scene.objects[2].pose};
  large.poses[0].rotateDegrees.y += 30.0;
  const auto renderer = makeCpuRenderer(scene, o);
  renderer->render(large);
  const Frame afterLarge = renderer->render(small);
  renderer->render(small);
  const Frame largeAgain = renderer->render(large);
  const Frame freshSmall = makeCpuRenderer(scene, o)->render(small);
  const Frame freshLarge = makeCpuRenderer(scene, o)->render(large);
  EXPECT_EQ(afterLarge.image.rgb, freshSmall.image.rgb);
  EXPECT_EQ(afterLarge.objectMask, freshSmall.objectMask);
  EXPECT_EQ(largeAgain.image.rgb, freshLarge.image.rgb);
}

TEST(CpuBackend, PosesAndLightChangeTheFrame) {
  const Scene scene = torusScene();
  RenderOptions o = tinyOptions();
  const auto renderer = makeCpuRenderer(scene, o);
  FrameRequest request;
  request.width = request.height = 24;
  request.camera = scene.camera;
  const Frame base = renderer->render(request);
  FrameRequest spun = request;
  spun.poses = {scene.objects.front().pose};
  spun.poses[0].rotateDegrees.y += 40.0;
  FrameRequest lit = request;
  lit.lightRotation = rotationAbout({0, 1, 0}, 90.0);
  EXPECT_NE(renderer->render(spun).image.rgb, base.image.rgb);
  EXPECT_NE(renderer->render(lit).image.rgb, base.image.rgb);
  FrameRequest wrong = request;
  wrong.poses.resize(2);
  EXPECT_THROW(renderer->render(wrong), std::invalid_argument);
}

}  // namespace
}  // namespace haarcast::render
