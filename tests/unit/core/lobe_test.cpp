// The lobe path's parts (core/lobe.h, core/prefiltered_light.h, fused.h):
// lobes measured against analytic values and the slice maps, the
// prefiltered light against its source, and the energy `fused` keeps.
#include "haarcast/core/lobe.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "haarcast/core/brdf.h"
#include "haarcast/core/brdf_slices.h"
#include "haarcast/core/fused.h"
#include "haarcast/core/prefiltered_light.h"
#include "haarcast/core/splitsum.h"
#include "test_maps.h"

namespace haarcast {
namespace {

TEST(Lobe, EnergyIsTheSliceMapsIntegral) {
  // A rough lobe the level-6 map resolves: its integral is ∫ρ·cos dω too.
  const auto ggx = makeGgx(glm::dvec3(0.2, 0.3, 0.1), glm::dvec3(0.9, 0.6, 0.5), 0.5);
  for (const double thetaOut : {0.1, 0.7, 1.3}) {
    const shared::SliceLobe lobe = measureLobe(*ggx, thetaOut);
    for (int c = 0; c < 3; ++c) {
      const double slice = sliceMap(*ggx, thetaOut, c, 6, 8).integral();
      EXPECT_NEAR(lobe.energy[c], slice, 0.01 * slice) << "θₒ " << thetaOut << " channel " << c;
    }
    EXPECT_FLOAT_EQ(lobe.energy.w, static_cast<float>(thetaOut)) << "the axis is the mirror direction";
  }
}

TEST(Lobe, LambertKeepsItsAlbedoAndIsWide) {
  const auto lambert = makeLambert(glm::dvec3(0.8));
  const shared::SliceLobe lobe = measureLobe(*lambert, 0.3);
  EXPECT_NEAR(lobe.energy.r, 0.8, 0.004);
  EXPECT_GT(lobe.median.x, 0.5) << "half of a cosine lobe lies beyond 29° of the mirror direction";
}

TEST(Lobe, GgxMedianIsTwiceItsRoughnessAndTheSamplesBandsWidenOutward) {
  // GGX's D puts half the microfacet normals within atan α of the normal
  // (P(θₕ < t) = tan²t/(α² + tan²t)); at normal incidence the reflected
  // direction turns by 2θₕ, so half the energy lies within ≈ 2α.
  for (const double alpha : {0.02, 0.05}) {
    const auto ggx = makeGgx(glm::dvec3(0.0), glm::dvec3(0.95), alpha);
    const shared::SliceLobe lobe = measureLobe(*ggx, 0.02);
    EXPECT_NEAR(lobe.median.x, 2.0 * std::atan(alpha), 0.1 * 2.0 * alpha) << "α " << alpha;
    EXPECT_NEAR(lobe.energy.r, 0.95, 0.05);
    // Band k's samples lie beyond band k − 1's and read a coarser level;
    // the weights are the energy's shares.
    constexpr shared::uint kJ = shared::kLobeSectors;
    float total = 0.0f;
    for (const glm::vec4& s : lobe.samples) total += s.w;
    EXPECT_NEAR(total, 1.0f, 1e-5f);
    for (shared::uint k = 1; k + 1 < shared::kLobeBands; ++k) {
      EXPECT_GT(lobe.samples[k * kJ].x, lobe.samples[(k - 1) * kJ].x) << "band " << k;
      EXPECT_LT(lobe.samples[k * kJ].z, lobe.samples[(k - 1) * kJ].z) << "band " << k;
    }
    EXPECT_LT(lobe.samples[kJ].x, lobe.median.x) << "band 1 ends at the median";
    EXPECT_GT(lobe.samples[2 * kJ].x, lobe.median.x) << "band 2 starts there";
  }
}

TEST(PrefilteredLight, EveryLevelKeepsTheIntegralAndAConstantLobeReadsTheConstant) {
  std::mt19937 rng(5);
  std::array<SphereMap, 3> maps;
  for (auto& m : maps) m = testing::randomMap(6, 0.0, 2.0, rng);
  const PrefilteredLight light = PrefilteredLight::build(maps);
  ASSERT_EQ(light.finestLevel(), 6);
  for (int l = 0; l <= 6; ++l) {
    double sum = 0.0;
    const std::span<const glm::vec4> t = light.texels().subspan(shared::prefilterOffset(static_cast<shared::uint>(l)));
    for (int r = 0; r < mapSize(l); ++r)
      for (int c = 0; c < mapSize(l); ++c) sum += t[static_cast<std::size_t>(r * mapSize(l) + c)].g * pixelSolidAngle(l, r);
    EXPECT_NEAR(sum, maps[1].integral(), 1e-4 * maps[1].integral()) << "level " << l;
  }
  // Level 0 is one texel, the mean: any lobe that reads only it gets it.
  shared::SliceLobe wide{};
  for (shared::uint i = 0; i < shared::kLobeSamples; ++i) {
    wide.samples[i] = glm::vec4(0.02f * static_cast<float>(i), 0.1f * static_cast<float>(i), -1.0f,  // level clamped to 0
                                1.0f / shared::kLobeSamples);
  }
  const glm::vec3 mean = light.lobe(wide, {0, 1, 0}, {1, 0, 0}, {0, 0, 1});
  EXPECT_NEAR(mean.g, maps[1].integral() / (4.0 * kPi), 1e-4);

  std::array<SphereMap, 3> flat{SphereMap(5, 1.5f), SphereMap(5, 1.5f), SphereMap(5, 1.5f)};
  const PrefilteredLight constant = PrefilteredLight::build(flat);
  shared::SliceLobe narrow{};
  for (shared::uint i = 0; i < shared::kLobeSamples; ++i) {
    narrow.samples[i] = glm::vec4(0.01f * static_cast<float>(i % 4 + 1), 0.7f * static_cast<float>(i), 4.3f - static_cast<float>(i % 4),
                                  1.0f / shared::kLobeSamples);
  }
  const glm::vec3 d = glm::normalize(glm::vec3(0.3f, 0.5f, -0.8f));
  const glm::vec3 u = glm::normalize(glm::cross(d, glm::vec3(0, 1, 0)));
  EXPECT_NEAR(constant.lobe(narrow, d, u, glm::cross(d, u)).b, 1.5f, 1e-5f);
}

TEST(PrefilteredLight, ACoarseTexelIsTheCapMeanAboutItsCentreEvenAtThePoles) {
  // A box-filtered lat-long texel next to a pole is a thin wedge from the
  // pole out, holding that wedge's mean rather than a mean about its
  // centre; the wedges around the pole then differ like a pinwheel on a
  // mirror's reflection of the zenith. Cap means are the same filter in
  // every direction: under L = 1 + x the mean over a cap of half-angle r
  // about d is 1 + d.x·(1 + cos r)/2, on every row.
  const std::array<SphereMap, 3> maps{SphereMap::fromFunction(8, [](const glm::dvec3& w) { return 1.0 + w.x; }),
                                      SphereMap(8, 1.0f), SphereMap(8, 1.0f)};
  const PrefilteredLight light = PrefilteredLight::build(maps);
  for (const int level : {3, 4, 5}) {
    const int m = mapSize(level);
    const double capCos = 1.0 - kPi / (static_cast<double>(m) * m);
    const std::span<const glm::vec4> t = light.texels().subspan(shared::prefilterOffset(static_cast<shared::uint>(level)));
    double worst = 0.0;
    for (int r = 0; r < m; ++r) {
      for (int c = 0; c < m; ++c) {
        const glm::dvec3 d = sphericalToDirection(rowTheta(level, r), colPhi(level, c));
        const double expected = 1.0 + d.x * (1.0 + capCos) / 2.0;
        worst = std::max(worst, std::abs(t[static_cast<std::size_t>(r * m + c)].r - expected));
      }
    }
    EXPECT_LT(worst, 0.01) << "level " << level;
  }
}

TEST(LobeCore, MirrorsTakeThePathHazyMirrorsTheirCoreRoughLobesNone) {
  const std::vector<double> thetaOut{0.2, 0.8, 1.3};
  // A near-mirror: all of the lobe within four level-5 texels.
  const LobeCore mirror = chooseLobeCore(*makeGgx(glm::dvec3(0.0), glm::dvec3(0.9), 0.002), thetaOut, 5);
  EXPECT_FLOAT_EQ(mirror.angle, static_cast<float>(kPi));
  ASSERT_EQ(mirror.lobes.size(), thetaOut.size());
  EXPECT_FLOAT_EQ(mirror.lobes[1].core.g, mirror.lobes[1].energy.g) << "the path carries all of the energy";
  // A mirror over a diffuse base (as measured chrome): the core by the path, the rest by the pass.
  const auto hazy = makeGgx(glm::dvec3(0.3), glm::dvec3(0.9), 0.005);
  const LobeCore split = chooseLobeCore(*hazy, thetaOut, 5);
  EXPECT_FLOAT_EQ(split.angle, static_cast<float>(kLobeCoreTexels * kPi / 32.0));
  for (const shared::SliceLobe& l : split.lobes) {
    EXPECT_LT(l.core.r, 0.95f * l.energy.r) << "the diffuse part is outside the core";
    EXPECT_GT(l.core.r, 0.3f * l.energy.r);
  }
  // Rough and glossy lobes, and a Lambert one: the maps resolve them.
  EXPECT_EQ(chooseLobeCore(*makeGgx(glm::dvec3(0.0), glm::dvec3(0.9), 0.3), thetaOut, 5).angle, 0.0f);
  EXPECT_EQ(chooseLobeCore(*makePhong(glm::dvec3(0.5), glm::dvec3(0.5), 64.0), thetaOut, 5).angle, 0.0f);
  const auto glossy = makeGgx(glm::dvec3(0.0), glm::dvec3(0.9), 0.05);
  EXPECT_GT(chooseLobeCore(*glossy, thetaOut, 5).angle, 0.0f) << "its median is under a level-5 texel";
  EXPECT_EQ(chooseLobeCore(*glossy, thetaOut, 6).angle, 0.0f) << "and over a level-6 one";
  const LobeCore lambert = chooseLobeCore(*makeLambert(glm::dvec3(0.8)), thetaOut, 5);
  EXPECT_EQ(lambert.angle, 0.0f);
  EXPECT_TRUE(lambert.lobes.empty());
}

TEST(ChooseLevel, LambertTakesTheFloorGlossyAMiddleLevelAMirrorTheCap) {
  // The table's θₒ at the default 16 slices (BrdfSliceTable, splitsum.h).
  const std::vector<double> thetaOut = lobeThetaOut(16);
  auto levelOf = [&](const Brdf& brdf, int cap) {
    const std::vector<shared::SliceLobe> lobes = measureLobes(brdf, thetaOut);
    std::printf("sharpest median %.4f rad (%.2f°): level %d of cap %d\n", sharpestMedian(lobes),
                sharpestMedian(lobes) * 180.0 / kPi, chooseLevel(lobes, cap), cap);
    return chooseLevel(lobes, cap);
  };
  const auto lambert = makeLambert(glm::dvec3(0.8));
  EXPECT_EQ(levelOf(*lambert, 6), kAutoLevelFloor);
  EXPECT_EQ(levelOf(*lambert, 7), kAutoLevelFloor);
  // ggx:0.3: its sharpest median (at the most grazing slice, where the
  // horizon cuts the lobe) m, and the level n = ⌈log₂(K·π/m)⌉ of the rule.
  const auto rough = makeGgx(glm::dvec3(0.0), glm::dvec3(0.9), 0.3);
  const std::vector<shared::SliceLobe> roughLobes = measureLobes(*rough, thetaOut);
  const double m = sharpestMedian(roughLobes);
  const int expected = static_cast<int>(std::ceil(std::log2(kLevelMedianTexels * kPi / m)));
  EXPECT_GT(expected, kAutoLevelFloor) << "a middle level";
  EXPECT_LT(expected, 7);
  EXPECT_EQ(levelOf(*rough, 7), expected);
  EXPECT_GE(m, kLevelMedianTexels * kPi / mapSize(expected)) << "its median spans K texels there";
  EXPECT_LT(m, kLevelMedianTexels * kPi / mapSize(expected - 1)) << "and not one level coarser";
  // A near-mirror is under K texels at any level `fused` takes: the cap.
  const auto mirror = makeGgx(glm::dvec3(0.0), glm::dvec3(0.9), 0.02);
  EXPECT_EQ(levelOf(*mirror, 6), 6);
  EXPECT_EQ(levelOf(*mirror, 7), 7);
  EXPECT_EQ(chooseLevel({}, 6), kAutoLevelFloor) << "no lobes: nothing to resolve";
  EXPECT_EQ(levelOf(*lambert, 3), 3) << "a cap below the floor wins";
}

TEST(ChooseLevel, ANearMirrorWhoseWholeLobeThePathTakesGetsTheCoarsestSuchLevel) {
  const std::vector<double> thetaOut = lobeThetaOut(16);
  // Step 2: where the lobe path takes the whole lobe, the coarsest level
  // at which it does. This near-mirror's whole lobe lies within 4 texels of
  // its axis at the floor, at every θₒ: the floor, whose pixels are the cap's.
  const auto mirror = makeGgx(glm::dvec3(0.0), glm::dvec3(0.9), 0.005);
  const std::vector<shared::SliceLobe> mirrorLobes = measureLobes(*mirror, thetaOut);
  EXPECT_EQ(chooseLevel(*mirror, thetaOut, mirrorLobes, 6), kAutoLevelFloor);
  EXPECT_FLOAT_EQ(chooseLobeCore(*mirror, thetaOut, kAutoLevelFloor, mirrorLobes).angle, static_cast<float>(kPi));
  // ggx:0.02's grazing slices spread past 4 texels of the floor (2 % of the
  // energy): its core is split off at every level, and it keeps the cap.
  const auto glossyMirror = makeGgx(glm::dvec3(0.0), glm::dvec3(0.9), 0.02);
  EXPECT_EQ(chooseLevel(*glossyMirror, thetaOut, measureLobes(*glossyMirror, thetaOut), 6), 6);
  // A mirror over a diffuse base (as measured chrome) has its core split
  // off at every level: the cap, where the pass resolves the most of the rest.
  const auto hazy = makeGgx(glm::dvec3(0.3), glm::dvec3(0.9), 0.005);
  EXPECT_EQ(chooseLevel(*hazy, thetaOut, measureLobes(*hazy, thetaOut), 6), 6);
  // Lobes without a path keep step 1's level.
  const auto rough = makeGgx(glm::dvec3(0.0), glm::dvec3(0.9), 0.3);
  const std::vector<shared::SliceLobe> roughLobes = measureLobes(*rough, thetaOut);
  EXPECT_EQ(chooseLevel(*rough, thetaOut, roughLobes, 6), chooseLevel(roughLobes, 6));
  EXPECT_GT(chooseLevel(roughLobes, 6), kAutoLevelFloor);
  const auto lambert = makeLambert(glm::dvec3(0.8));
  EXPECT_EQ(chooseLevel(*lambert, thetaOut, measureLobes(*lambert, thetaOut), 6), kAutoLevelFloor);
}

TEST(LobePath, SamplesFollowTheLobeWhereTheHorizonCutsIt) {
  // At a grazing view a GGX lobe is cut by the horizon and stretched along
  // the plane of incidence. Under a light that changes linearly, L = 1 + y
  // (y the normal), the lobe path's weighted samples must give the lobe's
  // own mean of L: Σ ρ·cos·L·ΔΩ / Σ ρ·cos·ΔΩ on a fine slice map. Samples
  // spread evenly about the mirror direction would read light below the
  // horizon and miss the mean.
  const auto ggx = makeGgx(glm::dvec3(0.0), glm::dvec3(0.9), 0.08);
  std::array<SphereMap, 3> maps;
  for (auto& m : maps) m = SphereMap::fromFunction(9, [](const glm::dvec3& w) { return 1.0 + w.y; });
  const PrefilteredLight light = PrefilteredLight::build(maps);
  for (const double thetaOut : {0.5, 1.35}) {
    const shared::SliceLobe lobe = measureLobe(*ggx, thetaOut);
    const SphereMap slice = sliceMap(*ggx, thetaOut, 0, 8, 4);
    double num = 0.0, den = 0.0;
    for (int r = 0; r < slice.size(); ++r) {
      for (int c = 0; c < slice.size(); ++c) {
        const double w = slice.at(r, c) * pixelSolidAngle(8, r);
        num += w * (1.0 + std::cos(rowTheta(8, r)));
        den += w;
      }
    }
    const float s = static_cast<float>(std::sin(thetaOut)), co = static_cast<float>(std::cos(thetaOut));
    const glm::vec3 got = light.lobe(lobe, {0.0f, co, -s}, {1.0f, 0.0f, 0.0f}, {0.0f, -s, -co});
    EXPECT_NEAR(got.r, num / den, 0.003 * num / den) << "θₒ " << thetaOut;
  }
}

TEST(LobePath, ShadesEnergyTimesTheLightWhereTheRaySeesAndNothingWhereNot) {
  std::array<SphereMap, 3> flat{SphereMap(5, 2.0f), SphereMap(5, 1.0f), SphereMap(5, 0.5f)};
  const PrefilteredLight light = PrefilteredLight::build(flat);
  const auto ggx = makeGgx(glm::dvec3(0.0), glm::dvec3(0.9, 0.7, 0.5), 0.02);
  const std::vector<shared::SliceLobe> lobes = measureLobes(*ggx, {0.3, 0.9});
  const LobePath path{&light, lobes, glm::mat3(1.0f)};  // the path takes all: E_core = E
  const shared::SliceBlend blend{0u, 1u, 0.25f};
  const EulerYXY r{0.4, 1.1, -0.7};
  const std::array<float, 3> seen = lobeShade(path, blend, r, shared::kLobeSeenBit);
  const std::array<float, 3> hidden = lobeShade(path, blend, r, 0u);
  const float flatLight[3] = {2.0f, 1.0f, 0.5f};
  for (int c = 0; c < 3; ++c) {
    const float energy = lobes[0].energy[c] + 0.25f * (lobes[1].energy[c] - lobes[0].energy[c]);
    EXPECT_NEAR(seen[static_cast<std::size_t>(c)], energy * flatLight[c], 1e-5f);
    EXPECT_EQ(hidden[static_cast<std::size_t>(c)], 0.0f);
  }
}

// A uniform unit light at level 4, and one point that sees every direction:
// under them a `fused` pixel is the energy its slice (or lobe) keeps.
struct UniformOpenSky {
  FusedLight light;
  VisibilityBits bits{4, 1};
  UniformOpenSky() {
    std::array<SphereMap, 3> unit{SphereMap(4, 1.0f), SphereMap(4, 1.0f), SphereMap(4, 1.0f)};
    for (auto& m : unit) m = m.weightedBySolidAngle();
    light = FusedLight::fromWeightedMaps(unit);
    bits.assign(std::vector<std::uint32_t>(bits.wordsPerPoint(), ~0u));
  }
  std::array<WeightedBits, 1> visibility() const { return {WeightedBits{bits.point(0).data(), 1.0f}}; }
};

// A level-4 slice table of four θₒ samples.
BrdfSliceTable level4Table(const Brdf& brdf) {
  SliceTableOptions options;
  options.level = 4;
  options.thetaSamples = 4;
  return BrdfSliceTable::build(brdf, options);
}

TEST(Fused, KeepsTheSlicesEnergyWhereTheMapsDirectionsMissPartOfANarrowLobe) {
  // Under a uniform unit light with V = 1, a pixel is ∫ρ: exactly the
  // slice's energy, whatever the rotation. The map's directions alone
  // count a lobe about a texel wide as they happen to fall on it (the
  // rotated map's integral below: off by percents), which showed as rings.
  const auto ggx = makeGgx(glm::dvec3(0.0), glm::dvec3(0.9), 0.06);
  const BrdfSliceTable table = level4Table(*ggx);
  const PixelSlices slices = PixelSlices::synthesize(table);
  const UniformOpenSky sky;
  const FusedLight& light = sky.light;
  const std::array<WeightedBits, 1> vis = sky.visibility();
  FusedScratch scratch;
  double worstRaw = 0.0;
  for (const EulerYXY& r : randomRotations(12, 3)) {
    const shared::SliceBlend blend{1u, 1u, 0.0f};
    const std::array<float, 3> got = fusedShade(slices, blend, r, light, vis, {}, 0u, scratch);
    const float energy = slices.energy(1)[0];
    EXPECT_NEAR(got[0], energy, 1e-4f * energy);
    const double raw = rotateSpatialMap(inverseHaar(table.slice(0, 1)), r).integral();
    worstRaw = std::max(worstRaw, std::abs(raw / energy - 1.0));
  }
  EXPECT_GT(worstRaw, 0.01) << "the lobe must be narrow enough for the map's directions to miss part of it";
}

TEST(Fused, ASplitLobeIsThePassOutsideTheCoreAndThePathInsideIt) {
  // A mirror over a diffuse base, split at two level-4 texels. Under a
  // uniform unit light with V = 1 the pixel is the lobe's energy: E − E_core
  // from the pass, E_core from the path; with the path's ray blocked, the
  // pass's part alone.
  const auto hazy = makeGgx(glm::dvec3(0.3), glm::dvec3(0.9), 0.005);
  const BrdfSliceTable table = level4Table(*hazy);
  const PixelSlices slices = PixelSlices::synthesize(table);
  std::vector<double> thetaOut;
  for (int t = 0; t < table.thetaSamples(); ++t) thetaOut.push_back(table.thetaOut(t));
  const LobeCore core = chooseLobeCore(*hazy, thetaOut, 4);
  ASSERT_GT(core.angle, 0.0f);
  ASSERT_LT(core.angle, static_cast<float>(kPi));
  const PrefilteredLight prefiltered =
      PrefilteredLight::build({SphereMap(4, 1.0f), SphereMap(4, 1.0f), SphereMap(4, 1.0f)});
  const UniformOpenSky sky;
  const FusedLight& light = sky.light;
  const std::array<WeightedBits, 1> vis = sky.visibility();
  const LobePath path{&prefiltered, core.lobes, glm::mat3(1.0f), core.angle};
  FusedScratch scratch;
  for (const EulerYXY& r : randomRotations(6, 4)) {
    const shared::SliceBlend blend{1u, 2u, 0.3f};
    const std::array<float, 3> got = fusedShade(slices, blend, r, light, vis, {}, shared::kLobeSeenBit, scratch, &path);
    const shared::SliceLobe l = shared::blendLobes(core.lobes[1], core.lobes[2], 0.3f);
    EXPECT_NEAR(got[0], l.energy.r, 1e-4f * l.energy.r);
    const std::array<float, 3> hidden = fusedShade(slices, blend, r, light, vis, {}, 0u, scratch, &path);
    EXPECT_NEAR(hidden[0], l.energy.r - l.core.r, 1e-4f * l.energy.r) << "the ray blocked: only the pass's part";
  }
}

}  // namespace
}  // namespace haarcast
