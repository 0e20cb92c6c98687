// Whole frames: the Vulkan backend against the CPU backend on the default
// scene (level 4, 64×64) for every rotation method, plus the renderer's
// contracts: no device allocation per frame, batching invisible in the
// result, clear errors for what the GPU cannot do.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <glm/geometric.hpp>

#include "frame_compare.h"
#include "gpu_test_util.h"
#include "haarcast/core/shared_cells.h"
#include "haarcast/core/shared_smooth.h"
#include "haarcast/core/fused.h"
#include "haarcast/core/shared_layout.h"
#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/gpu/vulkan_renderer.h"
#include "haarcast/render/exposure_meter.h"
#include "haarcast/render/renderer.h"

namespace haarcast::gpu {
namespace {

using testing::cacheDir;
using testing::compare;
using testing::Comparison;
using testing::frameOptions;
using testing::requestFor;
using testing::scenePoses;

// A target that turns the camera away from the objects and up from the
// ground (63° above the horizon: the frame's lower edge, 22.5° below its
// centre, stays above it).
glm::dvec3 lookingAway(const render::Camera& camera) {
  const glm::dvec3 back = camera.eye - camera.target;
  return camera.eye + glm::normalize(glm::dvec3(back.x, 0.0, back.z)) + glm::dvec3(0.0, 2.0, 0.0);
}

// A fused frame's stages: the host's shadow rays between the two submissions.
const std::vector<std::string> kFusedStages = {"light", "gbuffer", "rotation-input", "shadow-rays", "fused", "tonemap"};

// The stages in pipeline order under the shared names, some coefficient
// bytes read, and RGBA8 equal to the CPU encoding of the frame's own linear
// image (within two bytes of rounding).
void expectStagesAndRgba8(const render::Frame& b, const std::vector<std::string>& names, double exposureStops,
                          render::ToneCurve tone = render::ToneCurve::Reinhard) {
  EXPECT_EQ(b.exposureStops, exposureStops);
  ASSERT_EQ(b.stages.size(), names.size());
  for (std::size_t i = 0; i < names.size(); ++i) EXPECT_EQ(b.stages[i].name, names[i]);
  EXPECT_GT(b.coefficientBytes, 0u);
  const auto expected = render::tonemapRgba8(b.image, exposureStops, tone);
  ASSERT_EQ(expected.size(), b.rgba8.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < expected.size(); ++i) differ += expected[i] != b.rgba8[i];
  EXPECT_LE(differ, 2u) << render::toneCurveName(tone);
}

// Renders one frame on each backend and checks what the comparison promises.
void expectBackendsAgree(RotationMethod method, bool background) {
  const render::Scene scene = render::defaultScene();
  const render::RenderOptions o = frameOptions(method, background);
  const auto cpu = render::makeCpuRenderer(scene, o);
  VulkanRenderer gpu(scene, o, testing::testOptions());
  const render::FrameRequest request = requestFor(scene, o.width, o.height);
  const render::Frame a = cpu->render(request);
  const render::Frame b = gpu.render(request);
  const Comparison c = compare(a, b);
  std::printf("%s, %s background: PSNR %.1f dB (MSE %.3g) over %zu pixels; %zu of %zu object pixels mismatched\n",
              std::string(methodName(method)).c_str(), background ? "environment" : "black", c.psnr, c.mse, c.compared,
              c.mismatched, c.objectPixels);
  EXPECT_GE(c.psnr, 60.0);
  EXPECT_LE(static_cast<double>(c.mismatched), 0.005 * static_cast<double>(c.objectPixels) + 1.0);
  EXPECT_GT(c.objectPixels, 500u);
  expectStagesAndRgba8(b, {"light", "gbuffer", "rotation-input", "rotation", "triple-product", "tonemap"},
                       request.exposure.stops);
  testing::expectNoValidationMessages(gpu.context());
}

// Every method, with the environment behind the objects (objects and
// backdrop both compared).
class WholeFrame : public testing::GpuTestWithParam<RotationMethod> {};

TEST_P(WholeFrame, VulkanMatchesTheCpuBackendAbove60dB) {
  HAARCAST_REQUIRE_VULKAN();
  expectBackendsAgree(GetParam(), true);
}

// A black background: only the objects' pixels carry light.
GPU_TEST(WholeFrameBlack, VulkanMatchesTheCpuBackendAbove60dB) {
  HAARCAST_REQUIRE_VULKAN();
  expectBackendsAgree(RotationMethod::Haar, false);
}

INSTANTIATE_TEST_SUITE_P(Methods, WholeFrame,
                         ::testing::Values(RotationMethod::Haar, RotationMethod::Spatial, RotationMethod::Matrix,
                                           RotationMethod::Table),
                         [](const auto& param) { return std::string(methodName(param.param)); });

// The scene's poses with its second object and the light turned, so that
// the frames compare rotated slices and a light in each object's frame.
render::FrameRequest turnedRequest(const render::Scene& scene, const render::RenderOptions& o) {
  render::FrameRequest request = requestFor(scene, o.width, o.height);
  request.poses = scenePoses(scene);
  request.poses[1].rotateDegrees += glm::dvec3(10.0, 25.0, -5.0);
  request.lightRotation = rotationMatrix({0.3, -0.4, 0.1});
  return request;
}

// `fused` on Vulkan (fused.comp, one indirect dispatch) against the CPU
// backend's fused frame, levels 4–7, 64×64, environment backdrop. The floor
// is set below the measured PSNR (docs/gpu.md) with room for device
// differences; every object pixel must be covered alike.
class FusedFrame : public testing::GpuTestWithParam<int> {};

// The CPU backend's frame and the Vulkan renderer's of `scene` under `o`
// (turnedRequest), compared, with the figures printed under `what`.
struct FusedPair {
  render::FrameRequest request;
  render::Frame cpu, vulkan;
  Comparison c;
};
FusedPair renderFusedPair(const char* what, const render::Scene& scene, const render::RenderOptions& o, VulkanRenderer& gpu) {
  FusedPair p;
  p.request = turnedRequest(scene, o);
  p.cpu = render::makeCpuRenderer(scene, o)->render(p.request);
  p.vulkan = gpu.render(p.request);
  p.c = compare(p.cpu, p.vulkan);
  std::printf("%s, level %d: PSNR %.1f dB (MSE %.3g) over %zu pixels; %zu of %zu object pixels mismatched\n", what, o.level,
              p.c.psnr, p.c.mse, p.c.compared, p.c.mismatched, p.c.objectPixels);
  std::printf("  directions per sample: cpu %zu / %zu, vulkan %zu / %zu (most %zu, %zu)\n", p.cpu.passDirections,
              p.cpu.passSamples, p.vulkan.passDirections, p.vulkan.passSamples, p.cpu.passDirectionsMax,
              p.vulkan.passDirectionsMax);
  return p;
}

TEST_P(FusedFrame, VulkanMatchesTheCpuBackend) {
  HAARCAST_REQUIRE_VULKAN();
  const render::Scene scene = render::defaultScene();
  render::RenderOptions o = frameOptions(RotationMethod::Fused, true);
  o.level = GetParam();
  VulkanRenderer gpu(scene, o, testing::testOptions());
  const FusedPair p = renderFusedPair("fused", scene, o, gpu);
  const render::Frame& a = p.cpu;
  const render::Frame& b = p.vulkan;
  EXPECT_GE(p.c.psnr, testing::fusedPsnrFloor(gpu.context()));
  EXPECT_EQ(p.c.mismatched, 0u);
  EXPECT_GT(p.c.objectPixels, 500u);
  // The directions the pass visits (shared passRows, rows × M): the same
  // object samples on both; the rows may differ by one where acos rounds
  // differently at a row's edge, a few in a thousand.
  EXPECT_EQ(a.passSamples, b.passSamples);
  EXPECT_GT(a.passSamples, 500u);
  EXPECT_NEAR(static_cast<double>(b.passDirections), static_cast<double>(a.passDirections), 1e-3 * a.passDirections);
  EXPECT_EQ(a.passDirectionsMax, b.passDirectionsMax);
  EXPECT_LE(a.passDirectionsMax, std::size_t{1} << (2 * o.level));
  EXPECT_LT(a.passDirections, a.passSamples * (std::size_t{1} << (2 * o.level))) << "some rows are below every sample's cut";
  // The GPU counts what it reads: with the vertices' pixel forms (levels
  // 4–6 here), three planes of N floats per pixel instead of the lists.
  expectStagesAndRgba8(b, kFusedStages, p.request.exposure.stops);
  testing::expectNoValidationMessages(gpu.context());
}

INSTANTIATE_TEST_SUITE_P(Levels, FusedFrame, ::testing::Values(4, 5, 6, 7));

// The sum by cells (RenderOptions::sumTolerance, core/shared_cells.h) on
// both backends: the same cells coarse and fine, so the same frame and the
// same directions counted; levels 5 and 6 (cells start at 5), a Lambert
// sphere (all its cells coarse) beside the GGX torus. The device's cells
// that need 16 directions summed by their subgroup together, and each by
// its own invocation (VulkanRendererLimits::cellsTogether, the path of
// devices without subgroup ballot and shuffle).
class FusedCellsFrame : public testing::GpuTestWithParam<std::tuple<int, bool>> {};

TEST_P(FusedCellsFrame, VulkanMatchesTheCpuBackend) {
  HAARCAST_REQUIRE_VULKAN();
  render::Scene scene = render::defaultScene();
  scene.objects[0].material = render::materialFromSpec("lambert");
  render::RenderOptions o = frameOptions(RotationMethod::Fused, true);
  o.level = std::get<0>(GetParam());
  o.sumTolerance = shared::kDefaultSumTolerance;
  VulkanRendererLimits limits;
  limits.cellsTogether = std::get<1>(GetParam());
  VulkanRenderer gpu(scene, o, testing::testOptions(), {}, limits);
  const FusedPair p = renderFusedPair(limits.cellsTogether ? "fused by cells, subgroups together" : "fused by cells, lanes alone",
                                      scene, o, gpu);
  const render::Frame& a = p.cpu;
  const render::Frame& b = p.vulkan;
  EXPECT_GE(p.c.psnr, testing::fusedPsnrFloor(gpu.context()));
  EXPECT_EQ(p.c.mismatched, 0u);
  EXPECT_EQ(a.passSamples, b.passSamples);
  // A cell's detail read at a turned centre on a texel's edge may round
  // the other way: a few cells in ten thousand.
  EXPECT_NEAR(static_cast<double>(b.passDirections), static_cast<double>(a.passDirections), 2e-3 * a.passDirections);
  // By cells the pass sums far fewer directions than its rows hold.
  EXPECT_LT(a.passDirections * 4, a.passSamples * 3 * (std::size_t{1} << (2 * o.level)));
  testing::expectNoValidationMessages(gpu.context());
}

INSTANTIATE_TEST_SUITE_P(Levels, FusedCellsFrame, ::testing::Combine(::testing::Values(5, 6), ::testing::Bool()));

// The sum from a pixel's neighbours (RenderOptions::smoothSumTolerance,
// core/shared_smooth.h) on both backends: the device's dispatches, one a stage,
// coarse to fine, take the same pixels' sums as the CPU's pass and make the
// same frame; a Lambert sphere (whose sum is smooth) beside the GGX torus.
// Antialiased too: the edge pixels' sub-samples, which the rule does not
// visit, are summed in stage 0 beside the grid's pixels (fused.comp's lists).
class FusedSmoothFrame : public testing::GpuTestWithParam<bool> {};

TEST_P(FusedSmoothFrame, VulkanTakesTheSameSumsAsTheCpuBackend) {
  HAARCAST_REQUIRE_VULKAN();
  render::Scene scene = render::defaultScene();
  scene.objects[0].material = render::materialFromSpec("lambert");
  render::RenderOptions o = frameOptions(RotationMethod::Fused, true);
  o.width = o.height = 128;  // the sphere wide enough for its sum to be smooth over the grid's spacing
  o.antialias = GetParam();
  o.level = 5;
  o.sumTolerance = shared::kDefaultSumTolerance;
  o.smoothSumTolerance = shared::kDefaultSmoothSumTolerance;
  VulkanRenderer gpu(scene, o, testing::testOptions());
  const FusedPair p = renderFusedPair("fused, sums from neighbours", scene, o, gpu);
  const render::Frame& a = p.cpu;
  const render::Frame& b = p.vulkan;
  std::printf("  sums from neighbours: cpu %zu, vulkan %zu of %zu\n", a.smoothSamples, b.smoothSamples, a.passSamples);
  EXPECT_EQ(p.c.mismatched, 0u);
  if (o.antialias) {
    // The raster and Embree may cover an edge's sub-sample differently
    // (AntialiasFrame: a couple of edges); at 128² one sample does, and the
    // frames are 101.7 dB apart summing every pixel as with the sums from
    // neighbours.
    EXPECT_GE(p.c.psnr, 95.0);
    EXPECT_NEAR(static_cast<double>(b.passSamples), static_cast<double>(a.passSamples), 2.0);
  } else {
    EXPECT_GE(p.c.psnr, testing::fusedPsnrFloor(gpu.context()));
    EXPECT_EQ(a.passSamples, b.passSamples);
  }
  EXPECT_GT(a.smoothSamples, a.passSamples / 10) << "the test must see sums taken";
  // A decision on a threshold may round the other way: a few in a thousand.
  EXPECT_NEAR(static_cast<double>(b.smoothSamples), static_cast<double>(a.smoothSamples), 3e-3 * a.passSamples + 1.0);
  EXPECT_NEAR(static_cast<double>(b.passDirections), static_cast<double>(a.passDirections), 5e-3 * a.passDirections);
  // A sample that takes its sum reads no slice of the pass: counted alike
  // (but for the sub-samples the backends cover differently).
  if (o.antialias) {
    EXPECT_NEAR(static_cast<double>(b.coefficientBytes), static_cast<double>(a.coefficientBytes), 1e-3 * a.coefficientBytes);
  } else {
    EXPECT_EQ(b.coefficientBytes, a.coefficientBytes);
  }
  testing::expectNoValidationMessages(gpu.context());
}

INSTANTIATE_TEST_SUITE_P(Edges, FusedSmoothFrame, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& param) { return param.param ? "antialiased" : "aliased"; });

// Each object at its own level (RenderOptions::automaticLevel): the default
// scene with a Lambert sphere (the floor, 5) beside its GGX torus (6) and
// the ground (the floor), in one frame on both backends.
GPU_TEST(FusedFrame, ObjectsAtTheirOwnLevelsMatchTheCpuBackend) {
  HAARCAST_REQUIRE_VULKAN();
  render::Scene scene = render::defaultScene();
  scene.objects[0].material = render::materialFromSpec("lambert");
  render::RenderOptions o = frameOptions(RotationMethod::Fused, true);
  o.level = 6;
  o.automaticLevel = true;
  const auto cpu = render::makeCpuRenderer(scene, o);
  VulkanRenderer gpu(scene, o, testing::testOptions());
  const std::vector<int> levels = gpu.objectLevels();
  ASSERT_EQ(levels, cpu->objectLevels());
  ASSERT_EQ(levels.size(), 3u);
  EXPECT_EQ(levels[0], 5);
  EXPECT_EQ(levels[1], 6);
  EXPECT_EQ(levels[2], 5);
  const render::FrameRequest request = turnedRequest(scene, o);
  const render::Frame a = cpu->render(request);
  const render::Frame b = gpu.render(request);
  const Comparison c = compare(a, b);
  std::printf("fused, levels %d, %d, %d: PSNR %.1f dB (MSE %.3g) over %zu pixels; %zu of %zu object pixels mismatched\n",
              levels[0], levels[1], levels[2], c.psnr, c.mse, c.compared, c.mismatched, c.objectPixels);
  EXPECT_GE(c.psnr, testing::fusedPsnrFloor(gpu.context()));
  EXPECT_EQ(c.mismatched, 0u);
  EXPECT_GT(c.objectPixels, 500u);
  expectStagesAndRgba8(b, kFusedStages, request.exposure.stops);
  // The bytes read, which the device counts per object (one slice or two),
  // as the host counts them from the frame's own samples: the light, and per
  // sample of an object (not the ground) core fusedPixelBytes.
  const std::vector<RotationSample> rs = gpu.rotationSamples();
  const std::vector<ShadeSample> sh = gpu.shadeSamples();
  ASSERT_EQ(rs.size(), sh.size());
  std::size_t bytes = render::resolveFrame(gpu.prepared(), o, request).lightBytes, ground = 0;
  for (std::size_t i = 0; i < sh.size(); ++i) {
    const render::PreparedObject& p = gpu.prepared().objects.at(sh[i].object);
    if (p.ground) {
      ++ground;
      continue;
    }
    const shared::SliceBlend blend = shared::sliceBlendAt(rs[i].thetaOut, static_cast<shared::uint>(o.thetaSamples), 1u);
    const std::size_t visibilityBytes = 3 * shared::visibilityWords(static_cast<shared::uint>(p.level)) * sizeof(std::uint32_t);
    bytes += fusedPixelBytes(p.level, blend.weight != 0.0f && blend.second != blend.first, visibilityBytes);
  }
  EXPECT_GT(ground, 0u);
  EXPECT_EQ(b.coefficientBytes, bytes);
  testing::expectNoValidationMessages(gpu.context());
}

// The same with the lobe path (core/lobe.h chooseLobeCore): the sphere a
// near-mirror the path takes whole, the torus a mirror over a diffuse base
// it takes the core of, the pass the rest.
class FusedMirrorFrame : public testing::GpuTestWithParam<int> {};

TEST_P(FusedMirrorFrame, VulkanMatchesTheCpuBackend) {
  HAARCAST_REQUIRE_VULKAN();
  render::Scene scene = render::defaultScene();
  ASSERT_GE(scene.objects.size(), 2u);
  scene.objects[0].material = {"ggx:0.002", "test-mirror", makeGgx(glm::dvec3(0.0), glm::dvec3(0.9), 0.002), ""};
  scene.objects[1].material = {"hazy mirror", "test-hazy", makeGgx(glm::dvec3(0.3), glm::dvec3(0.9), 0.005), ""};
  render::RenderOptions o = frameOptions(RotationMethod::Fused, true);
  o.level = GetParam();
  // Every direction, then by cells (level 5): the cells near the lobe
  // path's core are summed fine on both backends.
  for (const float tolerance : {0.0f, shared::kDefaultSumTolerance}) {
    o.sumTolerance = tolerance;
    VulkanRenderer gpu(scene, o, testing::testOptions());
    const FusedPair p = renderFusedPair(tolerance > 0.0f ? "fused with the lobe path, by cells" : "fused with the lobe path",
                                        scene, o, gpu);
    EXPECT_GE(p.c.psnr, testing::fusedPsnrFloor(gpu.context()));
    EXPECT_EQ(p.c.mismatched, 0u);
    EXPECT_GT(p.c.objectPixels, 500u);
    EXPECT_NEAR(static_cast<double>(p.vulkan.passDirections), static_cast<double>(p.cpu.passDirections),
                2e-3 * p.cpu.passDirections);
    testing::expectNoValidationMessages(gpu.context());
  }
}

INSTANTIATE_TEST_SUITE_P(Levels, FusedMirrorFrame, ::testing::Values(4, 5));

// Auto exposure: the device's frame is metered and exposed as the CPU's
// (core/shared_exposure.h's rule on its own linear image, the same
// transform), and eases from a previous exposure by the fraction asked for.
GPU_TEST(VulkanRenderer, AutoExposureMatchesTheCpuBackend) {
  HAARCAST_REQUIRE_VULKAN();
  const render::Scene scene = render::defaultScene();
  const render::RenderOptions o = frameOptions(RotationMethod::Fused, true);
  const auto cpu = render::makeCpuRenderer(scene, o);
  VulkanRenderer gpu(scene, o, testing::testOptions());
  render::FrameRequest request = requestFor(scene, o.width, o.height);
  request.exposure = render::ExposureControl{};  // automatic, nothing to ease from
  const render::Frame a = cpu->render(request);
  const render::Frame b = gpu.render(request);
  ASSERT_GT(a.logAverageLuminance, 0.0);
  EXPECT_NEAR(b.logAverageLuminance, a.logAverageLuminance, 1e-3 * a.logAverageLuminance);
  EXPECT_NEAR(b.exposureStops, a.exposureStops, 1e-3);
  // On the device's own image the CPU's meter chooses the device's exposure.
  EXPECT_NEAR(b.exposureStops, render::meterExposure(b.image, b.objectMask, request.exposure, request.tone).stops, 1e-5);
  request.exposure.previousStops = a.exposureStops + 2.0;
  request.exposure.adaptation = 0.25;
  const render::Frame c = gpu.render(request);
  EXPECT_NEAR(c.exposureStops, a.exposureStops + 1.5, 1e-3);
  expectStagesAndRgba8(c, kFusedStages, c.exposureStops);
  testing::expectNoValidationMessages(gpu.context());
}

// Each tone curve: the device's bytes are its own linear image encoded by
// the CPU's transform with that curve, at a fixed and at the auto exposure.
GPU_TEST(VulkanRenderer, EveryToneCurveEncodesAsTheCpu) {
  HAARCAST_REQUIRE_VULKAN();
  const render::Scene scene = render::defaultScene();
  const render::RenderOptions o = frameOptions(RotationMethod::Fused, true);
  VulkanRenderer gpu(scene, o, testing::testOptions());
  render::FrameRequest request = requestFor(scene, o.width, o.height);
  for (const render::ToneCurve tone : render::kToneCurves) {
    request.tone = tone;
    request.exposure = render::ExposureControl{};
    request.exposure.automatic = false;
    request.exposure.stops = 0.75;
    const render::Frame fixed = gpu.render(request);
    expectStagesAndRgba8(fixed, kFusedStages, 0.75, tone);
    request.exposure = render::ExposureControl{};
    const render::Frame automatic = gpu.render(request);
    EXPECT_NEAR(automatic.exposureStops, render::meterExposure(automatic.image, automatic.objectMask, {}, tone).stops, 1e-5)
        << render::toneCurveName(tone);
    const auto expected = render::tonemapRgba8(automatic.image, automatic.exposureStops, tone);
    std::size_t differ = 0;
    for (std::size_t i = 0; i < expected.size(); ++i) differ += expected[i] != automatic.rgba8[i];
    // The gain multiplies on the device, the CPU divides the thresholds.
    EXPECT_LE(differ, expected.size() / 1000 + 2) << render::toneCurveName(tone);
  }
  testing::expectNoValidationMessages(gpu.context());
}

// The fused dispatch's shape does not change a bit of the image: as many
// workgroups as samples or 3 that loop over them all, 64 invocations or
// the default. A frame asked for RGBA8 only reads back no linear image and
// no mask, and encodes the same bytes at the same exposure; frames allocate
// no device memory.
GPU_TEST(VulkanRenderer, FusedDispatchShapeAndReadback) {
  HAARCAST_REQUIRE_VULKAN();
  const render::Scene scene = render::defaultScene();
  const render::RenderOptions o = frameOptions(RotationMethod::Fused, true);
  VulkanRenderer whole(scene, o, testing::testOptions());
  VulkanRendererLimits few;
  few.fusedGroups = 3;
  VulkanRenderer looped(scene, o, testing::testOptions(), {}, few);
  render::FrameRequest request = requestFor(scene, 40, 40);
  const render::Frame a = whole.render(request);
  const render::Frame b = looped.render(request);
  EXPECT_EQ(a.objectMask, b.objectMask);
  EXPECT_EQ(a.image.rgb, b.image.rgb) << "every sample is computed alone, whichever workgroup takes it";
  VulkanRendererLimits wide = few;
  wide.fusedLocalSize = 64;
  VulkanRenderer loopedWide(scene, o, testing::testOptions(), {}, wide);
  const render::Frame w = loopedWide.render(request);
  ASSERT_EQ(w.image.rgb.size(), a.image.rgb.size());
  // Another workgroup size sums the directions in another order: float rounding only.
  double worst = 0.0, peak = 0.0;
  for (std::size_t i = 0; i < a.image.rgb.size(); ++i) {
    worst = std::max(worst, std::abs(static_cast<double>(a.image.rgb[i]) - w.image.rgb[i]));
    peak = std::max(peak, std::abs(static_cast<double>(a.image.rgb[i])));
  }
  EXPECT_LT(worst, 1e-5 * peak);
  const std::uint64_t allocations = whole.context().allocationCount();
  request.linearImage = false;
  const render::Frame c = whole.render(request);
  EXPECT_TRUE(c.image.rgb.empty());
  EXPECT_TRUE(c.objectMask.empty()) << "the mask comes back with the linear image only";
  EXPECT_EQ(c.rgba8, a.rgba8);
  EXPECT_EQ(c.exposureStops, a.exposureStops);
  EXPECT_EQ(c.coefficientBytes, a.coefficientBytes);
  EXPECT_EQ(whole.context().allocationCount(), allocations) << "a fused frame allocated device memory";
  // An empty frame (the camera looks away): the indirect dispatch has no groups.
  request.linearImage = true;
  request.camera.target = lookingAway(scene.camera);
  const render::Frame d = whole.render(request);
  EXPECT_EQ(std::count(d.objectMask.begin(), d.objectMask.end(), 1), 0);
  testing::expectNoValidationMessages(whole.context());
  testing::expectNoValidationMessages(looped.context());
}

// Two frames in flight (VulkanRendererLimits::framesInFlight): two threads
// render at once, each in its own slot, and each frame is the one a renderer
// of one slot makes of the same request. Each frame's first cancel poll waits
// (bounded) until the other frame has polled too: were the frames rendered
// one after the other, the first would wait in vain.
GPU_TEST(VulkanRenderer, TwoFramesInFlightRenderAtOnceAndAsOne) {
  HAARCAST_REQUIRE_VULKAN();
  const render::Scene scene = render::defaultScene();
  const render::RenderOptions o = frameOptions(RotationMethod::Fused, true);
  VulkanRenderer one(scene, o, testing::testOptions());
  VulkanRendererLimits two;
  two.framesInFlight = 2;
  std::vector<std::string> reports;  // the build's progress: the second slot is a stage of its own, at the end
  VulkanRenderer slotted(scene, o, testing::testOptions(),
                         [&](const std::string& stage, std::size_t done, std::size_t total) {
                           reports.push_back(stage + " " + std::to_string(done) + "/" + std::to_string(total));
                         },
                         two);
  ASSERT_EQ(slotted.framesInFlight(), 2u);
  ASSERT_GE(reports.size(), 2u);
  EXPECT_EQ(reports[reports.size() - 2], "frame slots 1/2");
  EXPECT_EQ(reports.back(), "frame slots 2/2");
  ASSERT_TRUE(slotted.concurrentRenders());
  render::FrameRequest a = requestFor(scene, 40, 40), b = turnedRequest(scene, o);
  b.width = b.height = 40;
  std::mutex m;
  std::condition_variable cv;
  int started = 0, metTheOther = 0;
  auto waitForTheOther = [&] {
    std::unique_lock lock(m);
    ++started;
    cv.notify_all();
    if (cv.wait_for(lock, std::chrono::seconds(10), [&] { return started >= 2; })) ++metTheOther;
    return false;  // never cancelled
  };
  render::FrameRequest ca = a, cb = b;
  std::once_flag fa, fb;
  ca.cancelled = [&] { std::call_once(fa, waitForTheOther); return false; };
  cb.cancelled = [&] { std::call_once(fb, waitForTheOther); return false; };
  render::Frame ga, gb;
  std::thread t([&] { ga = slotted.render(ca); });
  gb = slotted.render(cb);
  t.join();
  EXPECT_EQ(metTheOther, 2) << "each frame saw the other inside render() at its first poll";
  EXPECT_EQ(slotted.peakFramesInFlight(), 2u);
  const render::Frame wa = one.render(a), wb = one.render(b);
  EXPECT_EQ(ga.image.rgb, wa.image.rgb);
  EXPECT_EQ(gb.image.rgb, wb.image.rgb);
  EXPECT_EQ(ga.rgba8, wa.rgba8);
  EXPECT_EQ(gb.rgba8, wb.rgba8);
  EXPECT_NE(ga.rgba8, gb.rgba8) << "the two requests are different views";
  testing::expectNoValidationMessages(one.context());
}

// A fused frame with the host's shadow rays polls the request's cancel
// before each of its two submissions and before the rays: cancelled at any
// of those points it stops with no images, and the next frame is whole.
// (With the device's rays a frame is one submission and polls once:
// DeviceRays.AFrameIsOneSubmission. The host's are pinned here, so a GPU
// that traces rays runs this path too.)
GPU_TEST(VulkanRenderer, FusedFrameCancelsBetweenItsSubmissions) {
  HAARCAST_REQUIRE_VULKAN();
  const render::Scene scene = render::defaultScene();
  const render::RenderOptions o = frameOptions(RotationMethod::Fused, true);
  VulkanRendererLimits hostRays;
  hostRays.rays = render::RayMode::Host;
  VulkanRenderer gpu(scene, o, testing::testOptions(), {}, hostRays);
  render::FrameRequest request = requestFor(scene, 32, 32);
  int polls = 0;
  request.cancelled = [&] { return ++polls < 0; };
  const render::Frame whole = gpu.render(request);
  ASSERT_FALSE(whole.cancelled);
  const int total = polls;
  EXPECT_GE(total, 3) << "two submissions and the shadow rays";
  for (int after = 0; after < total; ++after) {
    polls = 0;
    request.cancelled = [&, after] { return polls++ >= after; };
    const render::Frame f = gpu.render(request);
    EXPECT_TRUE(f.cancelled) << "cancelled after " << after << " polls";
    EXPECT_TRUE(f.rgba8.empty());
    EXPECT_EQ(polls, after + 1) << "nothing more polled once cancelled";
  }
  request.cancelled = {};
  const render::Frame again = gpu.render(request);
  EXPECT_FALSE(again.cancelled);
  EXPECT_EQ(again.image.rgb, whole.image.rgb);
  testing::expectNoValidationMessages(gpu.context());
}

// What a stage's device time went to (render::Frame::parts): on a device
// that times its stages with timestamps, each marked stage's parts, from
// mark to mark and the rest to its end, add up to the stage's time, in the
// order they were recorded; on a CPU device (host-timed stages) there are none.
GPU_TEST(VulkanRenderer, AFramesPartsAddUpToTheStagesTheyAreIn) {
  HAARCAST_REQUIRE_VULKAN();
  const render::Scene scene = render::defaultScene();
  render::RenderOptions o = frameOptions(RotationMethod::Fused, true);
  o.antialias = true;
  o.smoothSumTolerance = 0.01f;
  VulkanRenderer gpu(scene, o, testing::testOptions());
  const render::Frame f = gpu.render(requestFor(scene, 48, 32));
  if (gpu.context().info().type == "cpu") {
    EXPECT_TRUE(f.parts.empty());
    return;
  }
  std::vector<std::string> names;
  for (const render::StageTime& p : f.parts) names.push_back(p.name);
  const std::vector<std::string> want{"gbuffer: raster", "gbuffer: copies", "gbuffer: sub-sample raster",
                                      "gbuffer: sub-sample copies", "gbuffer: rest"};
  ASSERT_GE(names.size(), want.size());
  EXPECT_EQ(std::vector<std::string>(names.begin(), names.begin() + 5), want);
  for (const char* part : {"fused: uploads", "fused: grid sums", "fused: step 1 centres", "fused: rest", "tonemap: resolve",
                           "tonemap: exposure", "tonemap: tonemap", "tonemap: rest"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), part), names.end()) << part;
  }
  for (const render::StageTime& stage : f.stages) {
    double sum = 0.0;
    bool any = false;
    for (const render::StageTime& p : f.parts) {
      if (p.name.rfind(stage.name + ": ", 0) != 0) continue;
      any = true;
      EXPECT_GE(p.seconds, 0.0) << p.name;
      sum += p.seconds;
    }
    if (any) {
      EXPECT_NEAR(sum, stage.seconds, 1e-9 + 1e-6 * stage.seconds) << stage.name;
    }
  }
  testing::expectNoValidationMessages(gpu.context());
}

// Scene data and the light in device-local memory reached only through
// staging copies (the discrete-GPU path, forced here): the same frames, bit
// for bit, as with mapped memory, over frames whose light and poses change
// (each frame's light copy recorded again); frames allocate nothing.
void expectStagedInputsChangeNothing(RotationMethod method) {
  const render::Scene scene = render::defaultScene();
  const render::RenderOptions o = frameOptions(method, true);
  VulkanOptions stagedOptions = testing::testOptions();
  stagedOptions.stageInputs = true;
  VulkanRenderer direct(scene, o, testing::testOptions());
  VulkanRenderer staged(scene, o, stagedOptions);
  render::FrameRequest request = requestFor(scene, 32, 32);
  const render::Frame first = staged.render(request);
  EXPECT_EQ(first.image.rgb, direct.render(request).image.rgb);
  const std::uint64_t allocations = staged.context().allocationCount();
  request.poses = scenePoses(scene);
  request.poses[1].rotateDegrees += glm::dvec3(10.0, 25.0, -5.0);
  request.lightRotation = rotationMatrix({0.3, -0.4, 0.1});
  const render::Frame a = direct.render(request);
  const render::Frame b = staged.render(request);
  EXPECT_EQ(staged.context().allocationCount(), allocations) << "a staged frame allocated device memory";
  EXPECT_EQ(a.objectMask, b.objectMask);
  EXPECT_EQ(a.image.rgb, b.image.rgb);
  EXPECT_EQ(a.rgba8, b.rgba8);
  EXPECT_NE(a.image.rgb, first.image.rgb) << "the turned light changes the frame";
  testing::expectNoValidationMessages(direct.context());
  testing::expectNoValidationMessages(staged.context());
}

GPU_TEST(VulkanRenderer, StagedInputsChangeNothingFused) {
  HAARCAST_REQUIRE_VULKAN();
  expectStagedInputsChangeNothing(RotationMethod::Fused);
}

GPU_TEST(VulkanRenderer, StagedInputsChangeNothingHaar) {
  HAARCAST_REQUIRE_VULKAN();
  expectStagedInputsChangeNothing(RotationMethod::Haar);
}

GPU_TEST(VulkanRenderer, AllocatesDeviceMemoryOncePerResolution) {
  HAARCAST_REQUIRE_VULKAN();
  const render::Scene scene = render::defaultScene();
  const render::RenderOptions o = frameOptions(RotationMethod::Spatial, true);
  VulkanRenderer gpu(scene, o, testing::testOptions());
  render::FrameRequest request = requestFor(scene, 32, 32);
  gpu.render(request);
  const std::uint64_t afterFirst = gpu.context().allocationCount();
  request.poses = scenePoses(scene);
  request.poses[0].rotateDegrees = {0.0, 40.0, 0.0};
  request.lightRotation = rotationMatrix({0.5, 0.2, 0.0});
  for (int i = 0; i < 3; ++i) gpu.render(request);
  EXPECT_EQ(gpu.context().allocationCount(), afterFirst) << "frames at one resolution allocated device memory";
  request.width = 48;  // a new resolution reallocates once …
  gpu.render(request);
  const std::uint64_t afterResize = gpu.context().allocationCount();
  EXPECT_GT(afterResize, afterFirst);
  gpu.render(request);  // … and then not again
  EXPECT_EQ(gpu.context().allocationCount(), afterResize);
  testing::expectNoValidationMessages(gpu.context());
}

GPU_TEST(VulkanRenderer, BatchingTheRotationDoesNotChangeTheImage) {
  HAARCAST_REQUIRE_VULKAN();
  const render::Scene scene = render::defaultScene();
  const render::RenderOptions o = frameOptions(RotationMethod::Spatial, false);
  VulkanRenderer whole(scene, o, testing::testOptions());
  VulkanRendererLimits small;
  small.batchSamples = 97;
  VulkanRenderer batched(scene, o, testing::testOptions(), {}, small);
  const render::FrameRequest request = requestFor(scene, 40, 40);
  const render::Frame a = whole.render(request);
  const render::Frame b = batched.render(request);
  EXPECT_EQ(whole.batchesLastFrame(), 1u);
  EXPECT_GT(batched.batchesLastFrame(), 2u);
  EXPECT_EQ(a.objectMask, b.objectMask);
  EXPECT_EQ(a.image.rgb, b.image.rgb) << "every pixel is computed independently of its batch";
  // Batches are sized on the device from the covered count (batch_args.comp):
  // a frame with no covered pixel dispatches no rotation at all.
  render::FrameRequest away = requestFor(scene, 40, 40);
  away.camera.target = lookingAway(scene.camera);
  const render::Frame empty = batched.render(away);
  EXPECT_EQ(std::count(empty.objectMask.begin(), empty.objectMask.end(), 1), 0);
  EXPECT_EQ(batched.batchesLastFrame(), 0u);
  EXPECT_EQ(batched.render(request).image.rgb, b.image.rgb) << "the frame after an empty one";
  testing::expectNoValidationMessages(batched.context());
}

GPU_TEST(VulkanRenderer, RejectsWhatTheGpuCannotDoByName) {
  HAARCAST_REQUIRE_VULKAN();
  const render::Scene scene = render::defaultScene();
  render::RenderOptions o = frameOptions(RotationMethod::Spatial, false);
  o.level = 7;
  try {
    VulkanRenderer gpu(scene, o, testing::testOptions());
    FAIL() << "level 7 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("levels 2 to 6"), std::string::npos) << e.what();
  }
  o.level = 4;
  VulkanRenderer gpu(scene, o, testing::testOptions());
  render::FrameRequest bad = requestFor(scene, 16, 16);
  bad.poses.resize(5);
  EXPECT_THROW(gpu.render(bad), std::invalid_argument);
  bad = requestFor(scene, 0, 16);
  EXPECT_THROW(gpu.render(bad), std::invalid_argument);
  // A device that does not exist is an error that lists the devices.
  try {
    VulkanOptions v = testing::testOptions();
    v.device = "no-such-device";
    VulkanRenderer none(scene, o, v);
    FAIL() << "unknown device accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no-such-device"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace haarcast::gpu
