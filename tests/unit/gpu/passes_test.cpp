// Each Vulkan pass against the CPU reference on small inputs: the shaders
// driven alone with the renderer's data layouts (spatial rotation, triple
// product, tonemap), and the G-buffer and rotation-input passes read back
// from a real frame and checked pixel by pixel against Embree and
// render::rotationInput.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <glm/geometric.hpp>

#include "gpu_test_util.h"
#include "haarcast/assets/procedural_mesh.h"
#include "haarcast/core/rotation.h"
#include "haarcast/core/triple_product.h"
#include "haarcast/gpu/compute.h"
#include "haarcast/gpu/passes.h"
#include "haarcast/gpu/vulkan_renderer.h"
#include "haarcast/render/embree_scene.h"
#include "haarcast/render/shading.h"

namespace haarcast::gpu {
namespace {

// A glossy lobe plus noise: a slice-like map with sharp and fine detail.
HaarMap lobeMap(int level, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const glm::dvec3 axis = glm::normalize(glm::dvec3(u(rng), u(rng) + 1.2, u(rng)));
  const double sharpness = 10.0 + 20.0 * (u(rng) + 1.0);
  SphereMap map = SphereMap::fromFunction(level, [&](const glm::dvec3& d) {
    return std::exp(sharpness * (glm::dot(d, axis) - 1.0));
  });
  for (float& v : map.values()) v += static_cast<float>(0.05 * u(rng));
  return forwardHaar(map);
}

HaarMap randomMap(int level, std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  HaarMap m(level);
  for (float& c : m.coefficients()) c = u(rng);
  return m;
}

double maxAbs(std::span<const float> v) {
  double m = 0.0;
  for (float x : v) m = std::max(m, std::abs(static_cast<double>(x)));
  return m;
}

class SpatialRotationPass : public testing::GpuTestWithParam<int> {};

TEST_P(SpatialRotationPass, MatchesTheCpuRotatorCoefficientByCoefficient) {
  HAARCAST_REQUIRE_VULKAN();
  const int level = GetParam();
  const std::size_t n = static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level));
  std::mt19937 rng(7);
  // Two objects' worth of slices: 3 slices × 3 channels, global slice s.
  constexpr int kSlices = 3;
  std::vector<HaarMap> maps;
  std::vector<float> slices;
  for (int s = 0; s < kSlices * 3; ++s) {
    maps.push_back(lobeMap(level, rng));
    slices.insert(slices.end(), maps.back().coefficients().begin(), maps.back().coefficients().end());
  }
  const std::vector<EulerYXY> rotations = randomRotations(24, 11);
  std::vector<RotationSample> samples;
  for (std::size_t i = 0; i < rotations.size(); ++i) {
    RotationSample s{};
    s.slice = static_cast<std::uint32_t>(i % kSlices);
    s.alpha = static_cast<float>(rotations[i].alpha);
    s.beta = static_cast<float>(rotations[i].beta);
    s.gamma = static_cast<float>(rotations[i].gamma);
    s.pixel = static_cast<std::uint32_t>(i);
    samples.push_back(s);
  }
  // One sample exactly at the gimbal pole and one pure φ-shift.
  samples[0].beta = 0.0f;
  samples[1].beta = 0.0f;
  samples[1].gamma = 0.0f;

  Context context(testing::testOptions());
  Buffer sampleBuf(context, samples.size() * sizeof(RotationSample)), sliceBuf(context, slices.size() * 4),
      dummy(context, 4), out(context, samples.size() * 3 * n * 4);
  sampleBuf.upload(std::span<const RotationSample>(samples));
  sliceBuf.upload(std::span<const float>(slices));
  ComputePipeline p(context, "rotate_spatial.comp", shared::kRotateBindings, sizeof(shared::RotationPush),
                    {{shared::kSpecLevel, static_cast<std::uint32_t>(level)}, {shared::kSpecThetaSamples, kSlices}});
  p.bind({&sampleBuf, &sliceBuf, &dummy, &out});
  // Two dispatches (first = 0 and 10) to exercise the contract's offsets.
  const shared::RotationPush push[2] = {{0, 10, 0, 0}, {10, static_cast<std::uint32_t>(samples.size() - 10), 0, 0}};
  std::vector<float> rotated(samples.size() * 3 * n);
  for (const auto& pc : push) {
    context.submit([&](VkCommandBuffer cb) { p.dispatch(cb, {pc.count, 3, 1}, &pc, sizeof pc); });
    out.read(rotated.data() + pc.first * 3 * n, pc.count * 3 * n * 4);
  }

  double worst = 0.0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const EulerYXY r{samples[i].alpha, samples[i].beta, samples[i].gamma};
    for (int c = 0; c < 3; ++c) {
      const HaarMap& f = maps[samples[i].slice * 3 + static_cast<std::size_t>(c)];
      const HaarMap expected = rotateSpatial(f, r);
      const double scale = maxAbs(expected.coefficients());
      for (std::size_t k = 0; k < n; ++k) {
        const double err = std::abs(rotated[(i * 3 + static_cast<std::size_t>(c)) * n + k] - expected[k]) / scale;
        worst = std::max(worst, err);
      }
    }
  }
  std::printf("spatial rotation, level %d: max |gpu − cpu| / max|c| = %.3g\n", level, worst);
  EXPECT_LT(worst, 2e-5);
  testing::expectNoValidationMessages(context);
}

INSTANTIATE_TEST_SUITE_P(Levels, SpatialRotationPass, ::testing::Values(4, 5));

GPU_TEST(TripleProductPass, MatchesCoreTripleProductOnRandomSparseInputs) {
  HAARCAST_REQUIRE_VULKAN();
  for (const int level : {4, 5}) {
    const std::size_t n = static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level));
    std::mt19937 rng(static_cast<unsigned>(level));
    // 2 "objects" of light (3 channels each), 6 vertices of visibility,
    // truncated to various k, and 8 samples with random barycentrics.
    std::vector<SparseHaar> lights, vis;
    for (int i = 0; i < 6; ++i) lights.push_back(keepLargest(randomMap(level, rng), std::size_t{8} << i));
    for (int v = 0; v < 6; ++v) vis.push_back(keepLargest(randomMap(level, rng), v == 5 ? n : std::size_t{5} + 13 * v));
    vis[2].index.clear();  // an empty list: every term with V is zero
    vis[2].value.clear();
    constexpr int kSamples = 8;
    std::vector<HaarMap> brdf;
    std::vector<float> rotated;
    std::vector<ShadeSample> shade;
    std::vector<float> radianceInit(kSamples * 4, -7.0f);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int s = 0; s < kSamples; ++s) {
      ShadeSample sh{};
      sh.object = static_cast<std::uint32_t>(s % 2);
      for (int v = 0; v < 3; ++v) sh.vertex[v] = static_cast<std::uint32_t>((s + 2 * v) % 6);
      const float b1 = 0.5f * u(rng), b2 = 0.5f * u(rng);
      sh.b[0] = 1.0f - b1 - b2;
      sh.b[1] = b1;
      sh.b[2] = b2;
      sh.pixel = static_cast<std::uint32_t>(kSamples - 1 - s);
      shade.push_back(sh);
      for (int c = 0; c < 3; ++c) {
        brdf.push_back(randomMap(level, rng));
        rotated.insert(rotated.end(), brdf.back().coefficients().begin(), brdf.back().coefficients().end());
      }
    }
    const auto lightPacked = packSparseLists(lights, level);
    const auto visPacked = packSparseLists(vis, level);

    Context context(testing::testOptions());
    Buffer shadeBuf(context, shade.size() * sizeof(ShadeSample)), rotBuf(context, rotated.size() * 4),
        lightBuf(context, lightPacked.size() * 16), visBuf(context, visPacked.size() * 16),
        radBuf(context, radianceInit.size() * 4);
    shadeBuf.upload(std::span<const ShadeSample>(shade));
    rotBuf.upload(std::span<const float>(rotated));
    lightBuf.upload(std::span<const glm::uvec4>(lightPacked));
    visBuf.upload(std::span<const glm::uvec4>(visPacked));
    radBuf.upload(std::span<const float>(radianceInit));
    // The batch holds kSamples, the frame covered one fewer: the last
    // sample's invocations stop at the covered count (batch_args.comp sizes
    // the dispatch in whole groups of 64).
    const CoverageCounter covered{kSamples - 1, {0, 0, 0}};
    Buffer counterBuf(context, sizeof covered);
    counterBuf.write(&covered, sizeof covered);
    ComputePipeline p(context, "triple_product.comp", shared::kTripleProductBindings, sizeof(shared::RotationPush),
                      {{shared::kSpecLevel, static_cast<std::uint32_t>(level)}});
    p.bind({&shadeBuf, &rotBuf, &lightBuf, &visBuf, &radBuf, &counterBuf});
    const shared::RotationPush push{0, kSamples, 0, 0};
    context.submit([&](VkCommandBuffer cb) { p.dispatch(cb, {1, 1, 1}, &push, sizeof push); });
    std::vector<float> radiance(radianceInit.size());
    radBuf.download(std::span<float>(radiance));

    double worst = 0.0;
    for (int s = 0; s < kSamples; ++s) {
      const ShadeSample& sh = shade[static_cast<std::size_t>(s)];
      if (s == kSamples - 1) {
        for (int c = 0; c < 4; ++c) EXPECT_EQ(radiance[sh.pixel * 4 + static_cast<std::size_t>(c)], -7.0f) << "not covered";
        continue;
      }
      for (int c = 0; c < 3; ++c) {
        double expected = 0.0, magnitude = 0.0;
        for (int v = 0; v < 3; ++v) {
          const double t = tripleProduct(lights[sh.object * 3 + static_cast<std::size_t>(c)],
                                         brdf[static_cast<std::size_t>(s * 3 + c)], vis[sh.vertex[v]]);
          expected += sh.b[v] * t;
          magnitude += std::abs(sh.b[v] * t);
        }
        const double got = radiance[sh.pixel * 4 + static_cast<std::size_t>(c)];
        const double err = std::abs(got - expected) / std::max(1.0, magnitude);
        worst = std::max(worst, err);
        EXPECT_LT(err, 1e-4) << "level " << level << " sample " << s << " channel " << c << ": gpu " << got
                             << " cpu " << expected;
      }
      EXPECT_EQ(radiance[sh.pixel * 4 + 3], -7.0f) << "the pass wrote outside RGB";
    }
    std::printf("triple product, level %d: max relative error %.3g\n", level, worst);
    testing::expectNoValidationMessages(context);
  }
}

// batch_args.comp: every batch's indirect arguments from the covered count,
// a partial last batch and empty batches after it included.
GPU_TEST(BatchArgsPass, SizesEveryBatchFromTheCoveredCount) {
  HAARCAST_REQUIRE_VULKAN();
  constexpr std::uint32_t kBatch = 97, kBatches = 7;
  Context context(testing::testOptions());
  Buffer counterBuf(context, sizeof(CoverageCounter)), args(context, 2 * kBatches * sizeof(DispatchArgs));
  ComputePipeline p(context, "batch_args.comp", shared::kBatchArgsBindings, sizeof(shared::BatchArgsPush));
  p.bind({&counterBuf, &args});
  for (const std::uint32_t covered : {0u, 1u, 96u, 97u, 98u, 500u, kBatch * kBatches}) {
    const CoverageCounter c{covered, {0, 0, 0}};
    counterBuf.write(&c, sizeof c);
    const shared::BatchArgsPush push{kBatch, kBatches, 0, 0};
    context.submit([&](VkCommandBuffer cb) {
      p.dispatch(cb, {1, 1, 1}, &push, sizeof push);
      computeBarrier(cb);
    });
    std::vector<DispatchArgs> got(2 * kBatches);
    args.read(got.data(), got.size() * sizeof(DispatchArgs));
    for (std::uint32_t b = 0; b < kBatches; ++b) {
      const std::uint32_t first = b * kBatch;
      const std::uint32_t count = covered > first ? std::min(kBatch, covered - first) : 0u;
      EXPECT_EQ(got[b].groups[0], count) << "covered " << covered << ", batch " << b;
      EXPECT_EQ(got[b].groups[1], 3u);
      EXPECT_EQ(got[b].groups[2], 1u);
      EXPECT_EQ(got[kBatches + b].groups[0], (3 * count + 63) / 64) << "covered " << covered << ", batch " << b;
      EXPECT_EQ(got[kBatches + b].groups[1], 1u);
      EXPECT_EQ(got[kBatches + b].groups[2], 1u);
    }
  }
  testing::expectNoValidationMessages(context);
}

// Per tone curve (the curve lives in the thresholds the host computes).
class TonemapPass : public testing::GpuTestWithParam<render::ToneCurve> {};

TEST_P(TonemapPass, BackdropAndEncodingMatchTheCpuDefinitions) {
  HAARCAST_REQUIRE_VULKAN();
  const render::ToneCurve tone = GetParam();
  const int w = 40, h = 30, bgLevel = 5;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::array<SphereMap, 3> background;
  for (auto& map : background) {
    map = SphereMap(bgLevel);
    for (float& v : map.values()) v = 2.0f * u(rng);
  }
  render::Camera camera;
  camera.eye = {0.3, 0.5, 2.0};
  camera.fovYDegrees = 50.0;
  const glm::dmat3 lightRotation = rotationMatrix({0.4, 0.9, -0.3});
  const double exposure = -0.5;
  // Every other pixel covered, with radiance spanning black to over-exposed.
  const std::size_t pixels = static_cast<std::size_t>(w) * h;
  std::vector<glm::uvec4> ids(pixels, glm::uvec4(0));
  std::vector<glm::vec4> radiance(pixels, glm::vec4(0.0f));
  for (std::size_t i = 0; i < pixels; ++i) {
    if (i % 2) {
      ids[i].x = 1;
      radiance[i] = glm::vec4(3.0f * u(rng), 0.01f * u(rng), u(rng) - 0.1f, 0.0f);
    }
  }
  std::vector<float> bg;
  for (const auto& map : background) bg.insert(bg.end(), map.values().begin(), map.values().end());
  const FrameParams params = makeFrameParams(camera, w, h, lightRotation, true, bgLevel);

  Context context(testing::testOptions());
  Buffer paramBuf(context, sizeof params), idBuf(context, pixels * 16), radBuf(context, pixels * 16),
      bgBuf(context, bg.size() * 4), rgbaBuf(context, pixels * 4), thresholdBuf(context, sizeof(render::ToneThresholds)),
      edgeBuf(context, pixels * 4), exposureBuf(context, sizeof(ExposureResult));
  // A fixed exposure: in the thresholds, gain 1 (exposure.comp's choice for it).
  ExposureResult fixed{};
  fixed.gain = 1.0f;
  exposureBuf.write(&fixed, sizeof fixed);
  const auto thresholds = render::tonemapThresholds(exposure, tone);
  thresholdBuf.upload(std::span<const float>(thresholds));
  paramBuf.write(&params, sizeof params);
  idBuf.upload(std::span<const glm::uvec4>(ids));
  radBuf.upload(std::span<const glm::vec4>(radiance));
  bgBuf.upload(std::span<const float>(bg));
  ComputePipeline resolve(context, "resolve.comp", shared::kResolveBindings, 0),
      encode(context, "tonemap.comp", shared::kTonemapBindings, 0);
  resolve.bind({&paramBuf, &idBuf, &radBuf, &bgBuf, &edgeBuf});
  encode.bind({&paramBuf, &radBuf, &rgbaBuf, &thresholdBuf, &exposureBuf});
  context.submit([&](VkCommandBuffer cb) {
    resolve.dispatch(cb, {static_cast<std::uint32_t>((pixels + 63) / 64), 1, 1});
    computeBarrier(cb);
    encode.dispatch(cb, {static_cast<std::uint32_t>((pixels + 63) / 64), 1, 1});
  });
  std::vector<glm::vec4> linear(pixels);
  std::vector<std::uint8_t> rgba(pixels * 4);
  radBuf.download(std::span<glm::vec4>(linear));
  rgbaBuf.read(rgba.data(), rgba.size());

  // The CPU's image: covered pixels as given, the rest from backdropRadiance.
  const render::CameraRays rays(camera, w, h);
  io::RgbImage image = io::makeImage(w, h);
  double worstBackdrop = 0.0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * w + x;
      const glm::dvec3 expected = ids[p].x ? glm::dvec3(radiance[p])
                                           : glm::dvec3(render::backdropRadiance(background, glm::mat3(glm::transpose(lightRotation)),
                                                                                 glm::vec3(rays.direction(x, y))));
      for (int c = 0; c < 3; ++c) {
        image.at(y, x, c) = static_cast<float>(expected[c]);
        worstBackdrop = std::max(worstBackdrop, std::abs(linear[p][c] - expected[c]) / 2.0);
      }
    }
  }
  EXPECT_LT(worstBackdrop, 1e-5) << "backdrop differs from render::backdropRadiance";
  const std::vector<std::uint8_t> expected = render::tonemapRgba8(image, exposure, tone);
  ASSERT_EQ(expected.size(), rgba.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < rgba.size(); ++i) {
    EXPECT_LE(std::abs(int(rgba[i]) - int(expected[i])), 1) << "byte " << i;
    differ += rgba[i] != expected[i];
  }
  // Only a value within a float ulp of a rounding boundary may differ.
  EXPECT_LE(differ, 2u) << differ << " bytes differ by one";
  testing::expectNoValidationMessages(context);
}

INSTANTIATE_TEST_SUITE_P(Curves, TonemapPass, ::testing::ValuesIn(render::kToneCurves),
                         [](const auto& p) { return std::string(render::toneCurveName(p.param)); });

// ---- G-buffer and rotation-input, read back from a real frame ------------

render::Scene testScene() {
  render::Scene s;
  s.environment = render::constantEnvironment(1.0);
  auto sphere = std::make_shared<Mesh>(assets::makeSphere(24));
  auto torus = std::make_shared<Mesh>(assets::makeTorus(0.6, 0.22, 32, 16));
  render::SceneObject a{"sphere", sphere, render::materialFromSpec("phong:32"), {}};
  a.pose.translate = {-0.7, 0.1, 0.0};
  a.pose.scale = 0.6;
  render::SceneObject b{"torus", torus, render::materialFromSpec("lambert"), {}};
  b.pose.translate = {0.7, 0.0, -0.2};
  b.pose.rotateDegrees = {60.0, 20.0, 10.0};
  s.objects = {a, b};
  s.camera.eye = {0.2, 0.6, 3.0};
  return s;
}

render::RenderOptions tinyOptions() {
  render::RenderOptions o;
  o.width = o.height = 64;
  o.level = 4;
  o.thetaSamples = 8;
  o.sliceSupersampling = 1;
  o.visibility.supersampling = 1;
  o.method = RotationMethod::Spatial;
  return o;
}

// A hardware rasteriser snaps vertices to its sub-pixel grid (8 bits on
// NVIDIA) before it interpolates, so its barycentrics at a pixel centre are
// those of a point up to ~1/256 px away: tiny on screen, but on a
// triangle a fraction of a pixel wide, seen edge-on, up to 0.02 in
// barycentrics (measured on an H200). Lavapipe interpolates from unsnapped
// floats. So what is asserted on every device is what must hold: the
// G-buffer's point lies on its triangle at its own barycentrics, its
// normal is the mesh's at them, and it is seen through the pixel's centre
// to within a small fraction of a pixel; Embree's barycentrics are printed.
GPU_TEST(GBufferPass, CoverageAndSurfacePointsMatchEmbreeAtPixelCentres) {
  HAARCAST_REQUIRE_VULKAN();
  const render::Scene scene = testScene();
  const render::RenderOptions o = tinyOptions();
  VulkanRenderer gpu(scene, o, testing::testOptions());
  render::FrameRequest request;
  request.width = 64;
  request.height = 48;  // not square: aspect must follow CameraRays
  request.camera = scene.camera;
  gpu.render(request);
  const auto ids = gpu.gbufferIds();
  const auto normals = gpu.gbufferNormals();
  const auto positions = gpu.gbufferPositions();

  std::vector<Instance> instances;
  for (const auto& p : gpu.prepared().objects) instances.push_back({p.mesh.get(), glm::mat4(p.pose.objectToWorld())});
  const RayScene rays(std::move(instances));
  const render::CameraRays camera(scene.camera, request.width, request.height);
  std::size_t objectPixels = 0, mismatched = 0, sameTriangle = 0;
  double worstNormal = 0.0, worstOnTriangle = 0.0, worstScreen = 0.0, worstBary = 0.0;
  for (int y = 0; y < request.height; ++y) {
    for (int x = 0; x < request.width; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * request.width + x;
      Ray ray;
      ray.origin = glm::vec3(camera.origin());
      ray.direction = glm::vec3(camera.direction(x, y));
      const auto hit = rays.intersect(ray);
      const std::uint32_t cpuId = hit ? hit->object + 1 : 0;
      if (cpuId || ids[p].x) ++objectPixels;
      if (cpuId != ids[p].x) {
        ++mismatched;
        continue;
      }
      if (!ids[p].x) continue;
      if (hit && hit->triangle == ids[p].y) {
        ++sameTriangle;
        worstBary = std::max({worstBary, static_cast<double>(std::abs(std::bit_cast<float>(ids[p].z) - hit->u)),
                              static_cast<double>(std::abs(std::bit_cast<float>(ids[p].w) - hit->v))});
      }
      // The G-buffer's own triangle and barycentrics.
      const render::PreparedObject& object = gpu.prepared().objects[ids[p].x - 1];
      const Mesh& mesh = *object.mesh;
      ASSERT_LT(ids[p].y, mesh.triangles.size());
      const glm::uvec3 tri = mesh.triangles[ids[p].y];
      const double u = std::bit_cast<float>(ids[p].z), v = std::bit_cast<float>(ids[p].w);
      const double b[3] = {1.0 - u - v, u, v};
      const glm::dvec3 n = glm::normalize(b[0] * glm::dvec3(mesh.normals[tri.x]) + b[1] * glm::dvec3(mesh.normals[tri.y]) +
                                          b[2] * glm::dvec3(mesh.normals[tri.z]));
      const glm::dvec3 pos = b[0] * glm::dvec3(mesh.positions[tri.x]) + b[1] * glm::dvec3(mesh.positions[tri.y]) +
                             b[2] * glm::dvec3(mesh.positions[tri.z]);
      worstNormal = std::max(worstNormal, glm::length(glm::normalize(glm::dvec3(normals[p])) - n));
      worstOnTriangle = std::max(worstOnTriangle, glm::length(glm::dvec3(positions[p]) - pos));
      // Where the point is seen, in pixels from the pixel's centre.
      const glm::dvec3 world = glm::dvec3(object.pose.objectToWorld() * glm::dvec4(glm::dvec3(positions[p]), 1.0));
      const glm::dvec3 seen = glm::normalize(world - camera.origin());
      const double pixelAngle = glm::length(camera.directionAt(x + 1.5, y + 0.5) - camera.direction(x, y));
      worstScreen = std::max(worstScreen, glm::length(seen - camera.direction(x, y)) / pixelAngle);
    }
  }
  std::printf("G-buffer: %zu object pixels, %zu coverage mismatches, %zu on Embree's triangle (barycentrics within "
              "%.2g); its points: normal %.2g, off their triangle %.2g, %.2g px from the pixel centre\n",
              objectPixels, mismatched, sameTriangle, worstBary, worstNormal, worstOnTriangle, worstScreen);
  ASSERT_GT(objectPixels, 300u);
  EXPECT_LE(static_cast<double>(mismatched), 0.005 * static_cast<double>(objectPixels) + 1.0);
  EXPECT_GT(sameTriangle, objectPixels * 9 / 10);
  EXPECT_LT(worstNormal, 1e-3);
  EXPECT_LT(worstOnTriangle, 1e-4);
  EXPECT_LT(worstScreen, 0.05);
  testing::expectNoValidationMessages(gpu.context());
}

GPU_TEST(RotationInputPass, MatchesRenderRotationInputPerCoveredPixel) {
  HAARCAST_REQUIRE_VULKAN();
  const render::Scene scene = testScene();
  VulkanRenderer gpu(scene, tinyOptions(), testing::testOptions());
  render::FrameRequest request;
  request.width = request.height = 64;
  request.camera = scene.camera;
  request.poses = {scene.objects[0].pose, scene.objects[1].pose};
  request.poses[1].rotateDegrees = {10.0, 80.0, -30.0};  // a pose other than the scene's
  gpu.render(request);
  const auto ids = gpu.gbufferIds();
  const auto normals = gpu.gbufferNormals();
  const auto samples = gpu.rotationSamples();
  const auto shade = gpu.shadeSamples();
  ASSERT_EQ(samples.size(), shade.size());
  std::size_t covered = 0;
  for (const auto& id : ids) covered += id.x != 0;
  ASSERT_EQ(samples.size(), covered) << "compaction lost or duplicated pixels";

  const render::CameraRays camera(request.camera, request.width, request.height);
  std::vector<int> seen(ids.size(), 0);
  double worstRotation = 0.0;
  std::size_t sliceBoundary = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const RotationSample& s = samples[i];
    ASSERT_LT(s.pixel, ids.size());
    ASSERT_EQ(shade[i].pixel, s.pixel);
    ++seen[s.pixel];
    const std::uint32_t object = ids[s.pixel].x - 1;
    ASSERT_EQ(shade[i].object, object);
    const auto& prepared = gpu.prepared().objects[object];
    const int x = static_cast<int>(s.pixel % 64), y = static_cast<int>(s.pixel / 64);
    // The CPU definition, fed the G-buffer's own normal and the pixel's ray.
    const glm::dvec3 n = glm::normalize(glm::dvec3(normals[s.pixel]));
    const glm::dvec3 wo = glm::transpose(request.poses[object].rotation()) * -camera.direction(x, y);
    const render::RotationInput expected = render::rotationInput(n, wo, prepared.table);
    const std::uint32_t sliceBase = object == 0 ? 0u : static_cast<std::uint32_t>(gpu.prepared().objects[0].table.thetaSamples());
    double thetaOut = 0.0;
    render::shadingFrame(n, wo, thetaOut);
    const double cell = thetaOut / (kPi / 2.0) * prepared.table.thetaSamples();
    if (std::abs(cell - std::round(cell)) < 1e-4) {
      ++sliceBoundary;  // float and double may pick either neighbour here
    } else {
      EXPECT_EQ(s.slice, sliceBase + static_cast<std::uint32_t>(expected.slice)) << "pixel " << s.pixel;
    }
    // Compare rotations, not angles: at the gimbal pole the split of α and γ is arbitrary.
    const glm::dmat3 a = rotationMatrix(expected.euler);
    const glm::dmat3 b = rotationMatrix({s.alpha, s.beta, s.gamma});
    for (int c = 0; c < 3; ++c) worstRotation = std::max(worstRotation, glm::length(a[c] - b[c]));
    // The triangle's vertices, in the global numbering.
    const glm::uvec3 tri = prepared.mesh->triangles[ids[s.pixel].y];
    const std::uint32_t vertexBase = object == 0 ? 0u : static_cast<std::uint32_t>(gpu.prepared().objects[0].mesh->positions.size());
    EXPECT_EQ(shade[i].vertex[0], vertexBase + tri.x);
    EXPECT_EQ(shade[i].vertex[1], vertexBase + tri.y);
    EXPECT_EQ(shade[i].vertex[2], vertexBase + tri.z);
    EXPECT_NEAR(shade[i].b[0] + shade[i].b[1] + shade[i].b[2], 1.0, 1e-6);
  }
  for (std::size_t p = 0; p < ids.size(); ++p) EXPECT_EQ(seen[p], ids[p].x ? 1 : 0) << "pixel " << p;
  std::printf("rotation-input: %zu pixels, max |R_gpu − R_cpu| %.3g, %zu at a slice boundary\n", samples.size(),
              worstRotation, sliceBoundary);
  EXPECT_LT(worstRotation, 1e-4);
  testing::expectNoValidationMessages(gpu.context());
}

}  // namespace
}  // namespace haarcast::gpu
