// fused.comp driven alone against core fusedShade (its visibility-bits and
// point-light overload) on random inputs: random slice tables (one zero
// below the equator, which engages the skip), two objects with their own
// light and a ground, random rotations (one at the gimbal pole), random θₒ
// (blended and nearest slices), random visibility bits per vertex with
// barycentric weights, random point lights and random per-sample masks
// (bits past the light count set too: both sides must ignore them). The
// ground's samples against its closed form, groundRadiance + Σ_k bit_k·power_k.
// Fewer workgroups than samples, so each group loops over several samples,
// ground and not. The objects may sit at different map levels (ObjectInfo::
// level and its bases: docs/design.md, "A level per object"): object 2 at
// the case's second level, the others at its first.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "gpu_test_util.h"
#include "haarcast/core/brdf_slices.h"
#include "haarcast/core/fused.h"
#include "haarcast/core/shared_smooth.h"
#include "haarcast/core/visibility_bits.h"
#include "haarcast/gpu/compute.h"
#include "haarcast/gpu/passes.h"
#include "haarcast/render/point_lights.h"
#include "../core/test_maps.h"

namespace haarcast::gpu {
namespace {

using haarcast::testing::randomMap;

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
  bool interpolate;
  int other = 0;  // object 2's level; 0: `level` too
};

class FusedPass : public testing::GpuTestWithParam<PassCase> {};

TEST_P(FusedPass, MatchesCoreFusedShade) {
  HAARCAST_REQUIRE_VULKAN();
  const PassCase pc = GetParam();
  const int level = pc.level;
  constexpr int kThetaSamples = 4;
  constexpr std::size_t kPixels = 17;
  constexpr std::size_t kObjects = 4;           // three shaded by the loop (0, 1 with a lobe path), the ground last
  constexpr std::size_t kGround = 3;
  constexpr std::size_t kLights = 5;            // of kMaxPointLights; mask bits 5–7 must be ignored
  constexpr std::uint32_t kGroups = 5;          // fewer than the samples: groups loop
  std::mt19937 rng(static_cast<unsigned>(100 + level + 10 * pc.other));
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<int> levels(kObjects, level);
  if (pc.other) levels[2] = pc.other;  // a plain object (0 and 1 have lobe paths, 3 is the ground)
  auto directionsOf = [](int l) { return static_cast<std::size_t>(mapSize(l)) * static_cast<std::size_t>(mapSize(l)); };
  const DirectionTable directionTable = pixelCentreDirections(levels);

  // The objects: their slices (pixel form), light and point lights.
  std::vector<PixelSlices> slices;
  std::vector<FusedLight> lights;
  std::vector<std::vector<FusedPointLight>> pointLights(kObjects);
  std::vector<ObjectInfo> objects(kObjects);
  std::vector<float> texels, pointTexels;
  std::vector<glm::vec4> lightTexels;
  std::vector<PointLight> lightRecords(kObjects * shared::kMaxPointLights);
  for (std::size_t o = 0; o < kObjects; ++o) {
    const int l = levels[o];
    const std::size_t n = directionsOf(l);
    // The plain object's point lights read a finer table than its pass
    // (render::pointLightLevel), where its level allows one.
    const BrdfSliceTable table = randomTable(l, kThetaSamples, o == 1, rng);
    if (o == 2 && l < static_cast<int>(shared::kFusedMaxLevel)) {
      const BrdfSliceTable fine = randomTable(l + 1, kThetaSamples, false, rng);
      slices.push_back(PixelSlices::synthesize(table, &fine));
    } else {
      slices.push_back(PixelSlices::synthesize(table));
    }
    std::array<SphereMap, 3> weighted;
    for (auto& map : weighted) map = randomMap(l, 0.0, 0.02, rng);
    lights.push_back(FusedLight::fromWeightedMaps(weighted));
    objects[o].level = static_cast<std::uint32_t>(l);
    objects[o].sliceBase = static_cast<std::uint32_t>(o * kThetaSamples);
    objects[o].texelBase = static_cast<std::uint32_t>(texels.size() / shared::kTexelFloats);
    objects[o].pointLevel = static_cast<std::uint32_t>(slices[o].pointLevel());
    objects[o].pointTexelBase = static_cast<std::uint32_t>(pointTexels.size() / shared::kTexelFloats);
    objects[o].lightBase = static_cast<std::uint32_t>(lightTexels.size());
    objects[o].directionBase = directionTable.base[static_cast<std::size_t>(l)];
    objects[o].thetaSamples = kThetaSamples;
    objects[o].pointLights = static_cast<std::uint32_t>(kLights);
    setFusedSkip(objects[o], l, slices[o].lastNonZeroRow());
    texels.insert(texels.end(), slices[o].texels().begin(), slices[o].texels().end());
    pointTexels.insert(pointTexels.end(), slices[o].pointTexels().begin(), slices[o].pointTexels().end());
    lightTexels.resize(lightTexels.size() + n);
    fusedLightTexels(lights[o].planes, std::span<glm::vec4>(lightTexels).last(n));
    for (std::size_t k = 0; k < kLights; ++k) {
      FusedPointLight light;
      // Directions all over the sphere: some below the slices' cut (ρ = 0),
      // most not; powers of the order of the map's whole light.
      light.direction = glm::normalize(glm::vec3(2.0f * u(rng) - 1.0f, 2.0f * u(rng) - 1.0f, 2.0f * u(rng) - 1.0f));
      for (float& p : light.power) p = 0.5f + 2.0f * u(rng);
      pointLights[o].push_back(light);
      PointLight& r = lightRecords[o * shared::kMaxPointLights + k];
      r.direction = glm::vec4(light.direction, 0.0f);
      r.power = glm::vec4(light.power[0], light.power[1], light.power[2], 0.0f);
    }
  }
  objects[kGround].flags = shared::kObjectGround;
  // The sky other objects hide (HiddenLight): on the plain object and on
  // the one whose lobe path takes the core.
  constexpr std::size_t kPlain = 2;

  // The lobe path: object 1 takes all of its lobes by the path, object 0
  // their core (two texels about the axis) and the pass the rest; random
  // lobes (energies, cores, samples with levels some outside [0, finest]),
  // a random prefiltered light (finest level 5) and a random turn into its frame.
  constexpr std::size_t kLobeAll = 1, kLobeSplit = 0;
  constexpr int kPrefilterFinest = 5;
  const float coreAngle = 2.0f * static_cast<float>(kPi) / static_cast<float>(mapSize(levels[kLobeSplit]));
  std::vector<shared::SliceLobe> lobes(kObjects * kThetaSamples);
  std::vector<glm::vec4> energies;
  for (std::size_t o = 0; o < kObjects; ++o) {
    for (int t = 0; t < kThetaSamples; ++t) {
      const std::array<float, 3>& e = slices[o].energy(t);
      energies.emplace_back(e[0], e[1], e[2], 0.0f);
    }
  }
  for (const std::size_t o : {kLobeAll, kLobeSplit}) {
    for (int t = 0; t < kThetaSamples; ++t) {
      shared::SliceLobe& l = lobes[o * kThetaSamples + static_cast<std::size_t>(t)];
      l.energy = glm::vec4(u(rng), u(rng), u(rng), u(rng) * static_cast<float>(kPi / 2.0));
      l.core = glm::vec4(glm::vec3(l.energy) * u(rng), 0.0f);
      float total = 0.0f;
      for (glm::vec4& sample : l.samples) {
        sample = glm::vec4(0.3f * u(rng), 6.3f * u(rng), u(rng) * (kPrefilterFinest + 1.0f) - 0.5f, u(rng));
        total += sample.w;
      }
      for (glm::vec4& sample : l.samples) sample.w /= total;
    }
    objects[o].flags = shared::kObjectLobePath;
  }
  for (const std::size_t o : {kPlain, kLobeSplit}) objects[o].flags |= shared::kObjectSkyHidden;
  objects[kLobeAll].lobeCore = glm::vec4(-1.0f, 0.0f, 0.0f, 0.0f);
  objects[kLobeSplit].lobeCore = glm::vec4(std::cos(coreAngle), 0.0f, 0.0f, 0.0f);
  const glm::mat3 toLight(rotationMatrix(randomRotations(1, 7)[0]));
  for (const std::size_t o : {kLobeAll, kLobeSplit})
    for (int c = 0; c < 3; ++c) objects[o].toLight[c] = glm::vec4(toLight[c], 0.0f);
  std::array<SphereMap, 3> prefilterMaps;
  for (auto& map : prefilterMaps) map = randomMap(kPrefilterFinest, 0.0, 1.0, rng);
  const PrefilteredLight prefiltered = PrefilteredLight::build(prefilterMaps);
  objects[kGround].groundRadiance = glm::vec4(u(rng), u(rng), u(rng), 0.0f);

  // Samples: three vertices each (their random bits), a rotation, θₒ, a
  // mask. Each object has 3·kPixels vertices at its level (sample i's are
  // 3i … 3i + 2 of its object's), one after the other.
  std::vector<VisibilityBits> bits;
  std::vector<std::uint32_t> allWords;
  for (std::size_t o = 0; o < kObjects; ++o) {
    const std::size_t n = directionsOf(levels[o]);
    bits.emplace_back(levels[o], 3 * kPixels);
    std::vector<std::uint32_t> words(bits[o].pointCount() * bits[o].wordsPerPoint());
    std::uniform_int_distribution<std::uint32_t> word;
    const std::uint32_t spare = n < 32 ? (1u << n) - 1u : ~0u;  // no bit past the map's directions
    for (std::size_t w = 0; w < words.size(); ++w) words[w] = word(rng) & spare;
    bits[o].assign(words);
    ASSERT_EQ(bits[o].wordsPerPoint(), shared::visibilityWords(static_cast<shared::uint>(levels[o])));
    objects[o].vertexBase = static_cast<std::uint32_t>(o * 3 * kPixels);
    objects[o].visibilityBase = static_cast<std::uint32_t>(allWords.size());
    allWords.insert(allWords.end(), words.begin(), words.end());
  }
  std::vector<RotationSample> samples(kPixels);
  std::vector<ShadeSample> shade(kPixels);
  std::vector<std::uint32_t> masks(kPixels);
  std::vector<HiddenLight> hidden(kPixels, HiddenLight{});
  const std::vector<EulerYXY> rotations = randomRotations(kPixels, 23);
  for (std::size_t i = 0; i < kPixels; ++i) {
    RotationSample& s = samples[i];
    s.alpha = static_cast<float>(rotations[i].alpha);
    s.beta = i == 0 ? 0.0f : static_cast<float>(rotations[i].beta);  // sample 0 at the gimbal pole
    s.gamma = static_cast<float>(rotations[i].gamma);
    s.thetaOut = u(rng) * static_cast<float>(kPi / 2.0);
    s.pixel = static_cast<std::uint32_t>(i);
    ShadeSample& sh = shade[i];
    sh.object = static_cast<std::uint32_t>(i % kObjects);
    for (std::uint32_t v = 0; v < 3; ++v) sh.vertex[v] = objects[sh.object].vertexBase + static_cast<std::uint32_t>(3 * i + v);
    const float a = u(rng), b = u(rng) * (1.0f - a);
    sh.b[0] = a;
    sh.b[1] = b;
    sh.b[2] = 1.0f - a - b;
    sh.pixel = static_cast<std::uint32_t>(kPixels - 1 - i);  // not the sample order
    // Every light seen, none, and random masks (with bits past kLights).
    masks[i] = i < 3 ? 0xFFu : i < 6 ? 0u : static_cast<std::uint32_t>(rng() & 0xFFu);
    if (sh.object != kGround && i % 4 != 3) masks[i] |= shared::kLobeSeenBit;  // the lobe ray: mostly seen
    // Hidden sky on most samples of every object: read only where the
    // object's flag says so, and not at all with power 0.
    if (i % 3 != 0) {
      hidden[i].direction = shared::packDirection(glm::normalize(glm::vec3(2.0f * u(rng) - 1.0f, u(rng), 2.0f * u(rng) - 1.0f)));
      hidden[i].power = glm::vec3(0.5f + 2.0f * u(rng), 0.5f + 2.0f * u(rng), 0.5f + 2.0f * u(rng));
    }
  }
  const std::vector<glm::vec4>& dirs = directionTable.directions;
  const CoverageCounter counter{static_cast<std::uint32_t>(kPixels), {kGroups, 1, 1}};

  Context context(testing::testOptions());
  auto upload = [&](const void* data, std::size_t bytes) {
    Buffer b(context, bytes, kTexelUsage);
    b.write(data, bytes);
    return b;
  };
  Buffer sampleBuf = upload(samples.data(), samples.size() * sizeof(RotationSample));
  Buffer shadeBuf = upload(shade.data(), shade.size() * sizeof(ShadeSample));
  Buffer objectBuf = upload(objects.data(), objects.size() * sizeof(ObjectInfo));
  Buffer texelBuf = upload(texels.data(), texels.size() * sizeof(float));
  Buffer pointTexelBuf = upload(pointTexels.data(), pointTexels.size() * sizeof(float));
  Buffer lightBuf = upload(lightTexels.data(), lightTexels.size() * sizeof(glm::vec4));
  Buffer bitsBuf = upload(allWords.data(), allWords.size() * sizeof(std::uint32_t));
  Buffer dirBuf = upload(dirs.data(), dirs.size() * sizeof(glm::vec4));
  Buffer pointBuf = upload(lightRecords.data(), lightRecords.size() * sizeof(PointLight));
  Buffer radiance(context, kPixels * sizeof(glm::vec4));
  Buffer counterBuf = upload(&counter, sizeof counter);
  Buffer maskBuf = upload(masks.data(), masks.size() * sizeof(std::uint32_t));
  Buffer hiddenBuf = upload(hidden.data(), hidden.size() * sizeof(HiddenLight));
  Buffer energyBuf = upload(energies.data(), energies.size() * sizeof(glm::vec4));
  Buffer lobeBuf = upload(lobes.data(), lobes.size() * sizeof(shared::SliceLobe));
  Buffer prefilterBuf = upload(prefiltered.texels().data(), prefiltered.texels().size_bytes());
  const TexelView prefilterView(context, prefilterBuf, VK_FORMAT_R32G32B32A32_SFLOAT, sizeof(glm::vec4));
  const TexelView texelView(context, texelBuf, VK_FORMAT_R32G32B32A32_SFLOAT, sizeof(glm::vec4));
  const TexelView pointTexelView(context, pointTexelBuf, VK_FORMAT_R32G32B32A32_SFLOAT, sizeof(glm::vec4));
  const TexelView lightView(context, lightBuf, VK_FORMAT_R32G32B32A32_SFLOAT, sizeof(glm::vec4));
  const TexelView bitsView(context, bitsBuf, VK_FORMAT_R32_UINT, sizeof(std::uint32_t));
  const TexelView dirView(context, dirBuf, VK_FORMAT_R32G32B32A32_SFLOAT, sizeof(glm::vec4));
  // Every object sums every direction (ObjectInfo::sumTolerance 0): no detail map is read.
  const float noDetail = 0.0f;
  Buffer detailBuf = upload(&noDetail, sizeof noDetail);
  const TexelView detailView(context, detailBuf, VK_FORMAT_R32_SFLOAT, sizeof(float));
  Buffer smoothBuf(context, sizeof(glm::vec4));
  Buffer stageListsBuf(context, sizeof(std::uint32_t));
  ComputePipeline p(context, "fused.comp", fusedBindings(), sizeof(shared::FusedPush),
                    {{shared::kSpecLocalSize, shared::kLocalSize},
                     {shared::kSpecInterpolate, pc.interpolate ? 1u : 0u},
                     {shared::kSpecPrefilterFinest, static_cast<std::uint32_t>(kPrefilterFinest)}});
  constexpr std::size_t kWords = shared::kSliceCountsPerObject;
  std::vector<std::uint32_t> sliceCounts(kWords * objects.size(), 0u);
  Buffer sliceCountBuf = upload(sliceCounts.data(), sliceCounts.size() * sizeof(std::uint32_t));
  p.bind({&sampleBuf, &shadeBuf, &objectBuf, &texelView, &lightView, &bitsView, &dirView, &pointBuf, &radiance,
          &counterBuf, &maskBuf, &energyBuf, &lobeBuf, &prefilterView, &pointTexelView, &sliceCountBuf, &hiddenBuf,
          &detailView, &smoothBuf, &stageListsBuf});
  // Every sample shaded in one dispatch: no sum from neighbours (its own test: FusedFrame).
  shared::FusedPush push{};
  push.stage = shared::kSmoothSumOff;
  push.width = static_cast<std::uint32_t>(kPixels);
  push.height = 1u;
  context.submit([&](VkCommandBuffer cb) { p.dispatch(cb, {kGroups, 1, 1}, &push, sizeof push); });
  std::vector<glm::vec4> got(kPixels);
  radiance.read(got.data(), got.size() * sizeof(glm::vec4));
  sliceCountBuf.read(sliceCounts.data(), sliceCounts.size() * sizeof(std::uint32_t));
  // Per object: samples of one slice, of two; the pass's rows summed and the
  // most for one sample, from the CPU's own (FusedScratch::passDirections).
  std::vector<std::uint32_t> wantCounts(kWords * objects.size(), 0u);

  double worst = 0.0, scale = 0.0, lightShare = 0.0, hiddenTaken = 0.0;
  std::array<int, 2> lobeSamples{};  // samples all on the path, in part
  FusedScratch work;
  std::vector<std::array<float, 3>> expected(kPixels);
  for (std::size_t i = 0; i < kPixels; ++i) {
    const std::size_t o = shade[i].object;
    if (o == kGround) {
      // The closed form, in light order (CpuRenderer::shadeFused).
      expected[i] = {objects[o].groundRadiance.x, objects[o].groundRadiance.y, objects[o].groundRadiance.z};
      for (std::size_t k = 0; k < kLights; ++k)
        if ((masks[i] >> k) & 1u)
          for (std::size_t c = 0; c < 3; ++c) expected[i][c] += pointLights[o][k].power[c];
      ++wantCounts[kWords * o];  // the ground reads no slice: counted as one
      continue;
    }
    const shared::SliceBlend blend = shared::sliceBlendAt(samples[i].thetaOut, kThetaSamples, pc.interpolate ? 1u : 0u);
    ++wantCounts[kWords * o + (blend.weight != 0.0f && blend.second != blend.first ? 1 : 0)];
    const std::array<WeightedBits, 3> vis = {WeightedBits{bits[o].point(3 * i).data(), shade[i].b[0]},
                                             WeightedBits{bits[o].point(3 * i + 1).data(), shade[i].b[1]},
                                             WeightedBits{bits[o].point(3 * i + 2).data(), shade[i].b[2]}};
    const EulerYXY r{samples[i].alpha, samples[i].beta, samples[i].gamma};
    const LobePath path{&prefiltered,
                        std::span<const shared::SliceLobe>(lobes).subspan(o * kThetaSamples, kThetaSamples), toLight,
                        o == kLobeAll ? static_cast<float>(kPi) : coreAngle};
    const LobePath* lobe = o == kLobeAll || o == kLobeSplit ? &path : nullptr;
    if (lobe) lobeSamples[o == kLobeAll ? 0 : 1]++;
    const std::optional<std::array<float, 3>> sky =
        (objects[o].flags & shared::kObjectSkyHidden) != 0u ? render::hiddenIrradiance(hidden[i]) : std::nullopt;
    expected[i] = fusedShade(slices[o], blend, r, lights[o], vis, pointLights[o], masks[i], work, lobe, sky ? &*sky : nullptr);
    const auto rows = static_cast<std::uint32_t>(work.passDirections / static_cast<std::size_t>(mapSize(levels[o])));
    wantCounts[kWords * o + 2] += rows;
    wantCounts[kWords * o + 3] = std::max(wantCounts[kWords * o + 3], static_cast<std::uint32_t>(work.passDirections));
    if (sky) {
      const std::array<float, 3> open = fusedShade(slices[o], blend, r, lights[o], vis, pointLights[o], masks[i], work, lobe);
      for (std::size_t c = 0; c < 3; ++c)
        hiddenTaken = std::max(hiddenTaken, static_cast<double>(open[c] - expected[i][c]));
    }
    // How much of the sample the point lights make (the test must see them).
    const std::array<float, 3> mapOnly =
        fusedShade(slices[o], blend, r, lights[o], vis, pointLights[o], masks[i] & shared::kLobeSeenBit, work, lobe);
    for (std::size_t c = 0; c < 3; ++c) {
      lightShare = std::max(lightShare, static_cast<double>(expected[i][c] - mapOnly[c]) / std::max(1e-30f, expected[i][c]));
    }
    for (float x : expected[i]) scale = std::max(scale, std::abs(static_cast<double>(x)));
  }
  EXPECT_GT(lightShare, 0.1) << "the point lights make too little of any sample for the test to see them";
  // What the hidden sky takes, against the tolerance below: a pass that
  // ignored it would fail by far.
  EXPECT_GT(hiddenTaken / scale, 1e-3) << "the hidden sky takes too little of any sample for the test to see it";
  std::size_t groundSamples = 0;
  for (std::size_t i = 0; i < kPixels; ++i) {
    const glm::vec4& g = got[shade[i].pixel];
    if (shade[i].object == kGround) {
      ++groundSamples;
      for (int c = 0; c < 3; ++c) {
        EXPECT_FLOAT_EQ(g[c], expected[i][static_cast<std::size_t>(c)]) << "ground sample " << i << " channel " << c;
      }
      continue;
    }
    for (int c = 0; c < 3; ++c) {
      const double err = std::abs(g[c] - expected[i][static_cast<std::size_t>(c)]);
      worst = std::max(worst, err / scale);
    }
  }
  EXPECT_GT(groundSamples, 3u);
  // What the host counts the bytes read from (VulkanRenderer: core fusedPixelBytes).
  // Per object: samples of one slice and of two exactly; the pass's rows
  // summed and the most for one sample to a row a sample (passRows' acos
  // may round differently on a device where a row's edge falls).
  for (std::size_t o = 0; o < objects.size(); ++o) {
    const std::uint32_t* counted = sliceCounts.data() + kWords * o;
    const std::uint32_t* want = wantCounts.data() + kWords * o;
    EXPECT_EQ(counted[0], want[0]) << "object " << o << ": samples of one slice";
    EXPECT_EQ(counted[1], want[1]) << "object " << o << ": samples of two";
    EXPECT_NEAR(counted[2], want[2], want[0] + want[1]) << "object " << o << ": the pass's rows";
    EXPECT_NEAR(counted[3], want[3], mapSize(levels[o])) << "object " << o << ": the most directions for one sample (a row)";
    EXPECT_EQ(counted[4] + counted[5], 0u) << "object " << o << ": no cells";
  }
  EXPECT_GT(wantCounts[kWords * kPlain + 2], 0u) << "the plain object's samples ran the pass";
  std::printf("lobe path: %d samples all on it, %d in part\n", lobeSamples[0], lobeSamples[1]);
  EXPECT_GT(lobeSamples[0], 3);
  EXPECT_GT(lobeSamples[1], 3);
  std::printf("fused pass, level %d (object 2 at %d), %s: max |gpu − cpu| / max|I| = %.3g (point lights up to %.0f%% of a sample)\n",
              level, levels[2], pc.interpolate ? "blended slices" : "nearest slice", worst, 100.0 * lightShare);
  EXPECT_LT(worst, 1e-5);
  testing::expectNoValidationMessages(context);
}

INSTANTIATE_TEST_SUITE_P(Cases, FusedPass,
                         ::testing::Values(PassCase{2, true}, PassCase{4, true}, PassCase{4, false}, PassCase{5, false},
                                           PassCase{5, true}, PassCase{6, true}, PassCase{7, true},
                                           // Objects at two levels in one dispatch.
                                           PassCase{4, true, 6}, PassCase{6, false, 3}, PassCase{2, true, 7}),
                         [](const auto& c) {
                           return "level" + std::to_string(c.param.level) +
                                  (c.param.other ? "_and" + std::to_string(c.param.other) : std::string()) +
                                  (c.param.interpolate ? "_blend" : "_nearest");
                         });

}  // namespace
}  // namespace haarcast::gpu
