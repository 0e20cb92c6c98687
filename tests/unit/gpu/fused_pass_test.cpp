// fused.comp driven alone against core fusedShade on random inputs: random
// slice tables (some zero below the equator, which engages the skip), two
// objects with their own light, random rotations (one at the gimbal pole),
// random θₒ (blended and nearest slices) and random vertex visibility with
// barycentric weights. Scratch in shared and in global memory; fewer
// workgroups than pixels, so each group loops over several pixels.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "gpu_test_util.h"
#include "haarcast/core/brdf_slices.h"
#include "haarcast/core/fused.h"
#include "haarcast/gpu/compute.h"
#include "haarcast/gpu/passes.h"
#include "../core/test_maps.h"

namespace haarcast::gpu {
namespace {

using haarcast::testing::randomSparse;

BrdfSliceTable randomTable(int level, int thetaSamples, bool upperOnly, std::mt19937& rng) {
  std::uniform_real_distribution<double> dist(0.05, 1.0);
  std::vector<double> thetaOut;
  for (int t = 0; t < thetaSamples; ++t) thetaOut.push_back((t + 0.5) * (kPi / 2.0) / thetaSamples);
  std::vector<HaarMap> slices;
  for (int c = 0; c < 3; ++c) {
    for (int t = 0; t < thetaSamples; ++t) {
      SphereMap map(level);
      for (int i = 0; i < map.size(); ++i) {
        for (int j = 0; j < map.size(); ++j) {
          map.at(i, j) = (upperOnly && i >= map.size() / 2) ? 0.0f : static_cast<float>(dist(rng));
        }
      }
      slices.push_back(forwardHaar(map));
    }
  }
  return BrdfSliceTable::fromSlices(std::move(thetaOut), std::move(slices));
}

struct PassCase {
  int level;
  bool sharedScratch;
  bool interpolate;
  bool vertexPlanes;  // visibility per vertex in pixel form (else the lists, merged per pixel)
};

class FusedPass : public ::testing::TestWithParam<PassCase> {};

TEST_P(FusedPass, MatchesCoreFusedShade) {
  HAARCAST_REQUIRE_VULKAN();
  const PassCase pc = GetParam();
  const int level = pc.level;
  constexpr int kThetaSamples = 4;
  constexpr std::size_t kPixels = 13;
  constexpr std::uint32_t kGroups = 5;  // fewer than the pixels: groups loop
  std::mt19937 rng(static_cast<unsigned>(100 + level));

  // Two objects: their slices (pixel form) and light.
  std::vector<PixelSlices> slices;
  std::vector<FusedLight> lights;
  std::vector<ObjectInfo> objects(2);
  std::vector<float> texels;
  std::vector<glm::vec4> lightTexels;
  for (std::size_t o = 0; o < 2; ++o) {
    slices.push_back(PixelSlices::synthesize(randomTable(level, kThetaSamples, o == 1, rng)));
    std::array<SparseHaar, 3> light;
    for (auto& l : light) l = randomSparse(level, 64, -0.3, 0.3, rng);
    lights.push_back(FusedLight::synthesize(light));
    objects[o].sliceBase = static_cast<std::uint32_t>(o * kThetaSamples);
    objects[o].thetaSamples = kThetaSamples;
    setFusedSkip(objects[o], level, slices[o].lastNonZeroRow());
    texels.insert(texels.end(), slices[o].texels().begin(), slices[o].texels().end());
    lightTexels.resize(lightTexels.size() + lights[o].planes.size() / 3);
    fusedLightTexels(lights[o].planes, std::span<glm::vec4>(lightTexels).last(lights[o].planes.size() / 3));
  }

  // Pixels: three vertex lists each, a rotation, θₒ.
  std::vector<SparseHaar> visibility;
  std::vector<RotationSample> samples(kPixels);
  std::vector<ShadeSample> shade(kPixels);
  const std::vector<EulerYXY> rotations = randomRotations(kPixels, 23);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (std::size_t i = 0; i < kPixels; ++i) {
    for (int v = 0; v < 3; ++v) visibility.push_back(randomSparse(level, 16 + 20 * static_cast<std::size_t>(v), -0.5, 0.5, rng));
    RotationSample& s = samples[i];
    s.alpha = static_cast<float>(rotations[i].alpha);
    s.beta = i == 0 ? 0.0f : static_cast<float>(rotations[i].beta);  // pixel 0 at the gimbal pole
    s.gamma = static_cast<float>(rotations[i].gamma);
    s.thetaOut = u(rng) * static_cast<float>(kPi / 2.0);
    s.pixel = static_cast<std::uint32_t>(i);
    ShadeSample& sh = shade[i];
    sh.object = static_cast<std::uint32_t>(i % 2);
    for (std::uint32_t v = 0; v < 3; ++v) sh.vertex[v] = static_cast<std::uint32_t>(3 * i + v);
    const float a = u(rng), b = u(rng) * (1.0f - a);
    sh.b[0] = a;
    sh.b[1] = b;
    sh.b[2] = 1.0f - a - b;
    sh.pixel = static_cast<std::uint32_t>(kPixels - 1 - i);  // not the sample order
  }
  std::vector<std::uint32_t> visWords;
  if (pc.vertexPlanes) {
    for (const SparseHaar& v : visibility) {
      const SphereMap pixels = inverseHaar(v.toDense());
      for (float x : pixels.values()) visWords.push_back(std::bit_cast<std::uint32_t>(x));
    }
  } else {
    visWords = packVisibilityEntries(visibility, level);
  }
  const std::vector<glm::vec4> dirs = pixelCentreDirections(level);
  const CoverageCounter counter{static_cast<std::uint32_t>(kPixels), {kGroups, 1, 1}};

  Context context(testing::testOptions());
  const std::size_t floats = fusedScratchFloats(level, pc.vertexPlanes);
  const std::uint32_t local = 64;
  if (pc.sharedScratch &&
      floats * sizeof(float) + local * 16 > context.properties().limits.maxComputeSharedMemorySize) {
    GTEST_SKIP() << "the device's shared memory does not hold a level-" << level << " scratch";
  }
  auto upload = [&](const void* data, std::size_t bytes) {
    Buffer b(context, bytes, kTexelUsage);
    b.write(data, bytes);
    return b;
  };
  Buffer sampleBuf = upload(samples.data(), samples.size() * sizeof(RotationSample));
  Buffer shadeBuf = upload(shade.data(), shade.size() * sizeof(ShadeSample));
  Buffer objectBuf = upload(objects.data(), objects.size() * sizeof(ObjectInfo));
  Buffer texelBuf = upload(texels.data(), texels.size() * sizeof(float));
  Buffer lightBuf = upload(lightTexels.data(), lightTexels.size() * sizeof(glm::vec4));
  Buffer visBuf = upload(visWords.data(), visWords.size() * sizeof(std::uint32_t));
  Buffer dirBuf = upload(dirs.data(), dirs.size() * sizeof(glm::vec4));
  Buffer scratch(context, pc.sharedScratch ? 4 : kGroups * floats * sizeof(float));
  Buffer radiance(context, kPixels * sizeof(glm::vec4));
  Buffer counterBuf = upload(&counter, sizeof counter);
  const TexelView texelView(context, texelBuf, VK_FORMAT_R32G32B32A32_SFLOAT, sizeof(glm::vec4));
  const TexelView lightView(context, lightBuf, VK_FORMAT_R32G32B32A32_SFLOAT, sizeof(glm::vec4));
  const TexelView dirView(context, dirBuf, VK_FORMAT_R32G32B32A32_SFLOAT, sizeof(glm::vec4));
  const TexelView planeView(context, visBuf, VK_FORMAT_R32_SFLOAT, sizeof(float));  // read only with planes
  ComputePipeline p(context, "fused.comp", fusedBindings(), 0,
                    {{0, static_cast<std::uint32_t>(level)},
                     {2, local},
                     {3, pc.sharedScratch && floats > 0 ? static_cast<std::uint32_t>(floats) : 1u},
                     {4, pc.interpolate ? 1u : 0u},
                     {5, pc.vertexPlanes ? 1u : 0u}});
  p.bind({&sampleBuf, &shadeBuf, &objectBuf, &texelView, &lightView, &visBuf, &dirView, &scratch, &radiance, &counterBuf,
          &planeView});
  context.submit([&](VkCommandBuffer cb) { p.dispatch(cb, {kGroups, 1, 1}); });
  std::vector<glm::vec4> got(kPixels);
  radiance.read(got.data(), got.size() * sizeof(glm::vec4));

  double worst = 0.0, scale = 0.0;
  FusedScratch work;
  std::vector<std::array<float, 3>> expected(kPixels);
  for (std::size_t i = 0; i < kPixels; ++i) {
    const std::size_t o = shade[i].object;
    const shared::SliceBlend blend = shared::sliceBlendAt(samples[i].thetaOut, kThetaSamples, pc.interpolate ? 1u : 0u);
    const std::array<WeightedVisibility, 3> vis = {WeightedVisibility{&visibility[3 * i], shade[i].b[0]},
                                                   WeightedVisibility{&visibility[3 * i + 1], shade[i].b[1]},
                                                   WeightedVisibility{&visibility[3 * i + 2], shade[i].b[2]}};
    const EulerYXY r{samples[i].alpha, samples[i].beta, samples[i].gamma};
    expected[i] = fusedShade(slices[o], blend, r, lights[o], vis, work);
    for (float x : expected[i]) scale = std::max(scale, std::abs(static_cast<double>(x)));
  }
  for (std::size_t i = 0; i < kPixels; ++i) {
    for (int c = 0; c < 3; ++c) {
      const double err = std::abs(got[shade[i].pixel][c] - expected[i][static_cast<std::size_t>(c)]);
      worst = std::max(worst, err / scale);
    }
  }
  std::printf("fused pass, level %d, %s scratch, %s, %s: max |gpu − cpu| / max|I| = %.3g\n", level,
              pc.sharedScratch ? "shared" : "global", pc.interpolate ? "blended slices" : "nearest slice",
              pc.vertexPlanes ? "vertex planes" : "vertex lists", worst);
  EXPECT_LT(worst, 1e-5);
  testing::expectNoValidationMessages(context);
}

INSTANTIATE_TEST_SUITE_P(Cases, FusedPass,
                         ::testing::Values(PassCase{4, true, true, false}, PassCase{4, false, false, false},
                                           PassCase{5, true, false, true}, PassCase{5, true, true, true},
                                           PassCase{6, false, true, false}, PassCase{7, false, true, true}),
                         [](const auto& c) {
                           return "level" + std::to_string(c.param.level) +
                                  (c.param.sharedScratch ? "_shared" : "_global") +
                                  (c.param.interpolate ? "_blend" : "_nearest") +
                                  (c.param.vertexPlanes ? "_planes" : "_lists");
                         });

}  // namespace
}  // namespace haarcast::gpu
