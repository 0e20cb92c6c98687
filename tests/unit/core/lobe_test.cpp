// The lobe path's parts (core/lobe.h, core/prefiltered_light.h, fused.h):
// lobes measured against analytic values and the slice maps, the
// prefiltered light against its source, and the energy `fused` keeps.
#include "haarcast/core/lobe.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "haarcast/core/brdf.h"
#include "haarcast/core/brdf_slices.h"
#include "haarcast/core/fused.h"
#include "haarcast/core/prefiltered_light.h"
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

TEST(Lobe, GgxMedianIsTwiceItsRoughnessAndTheRingsSplitItEvenly) {
  // GGX's D puts half the microfacet normals within atan α of the normal
  // (P(θₕ < t) = tan²t/(α² + tan²t)); at normal incidence the reflected
  // direction turns by 2θₕ, so half the energy lies within ≈ 2α.
  for (const double alpha : {0.02, 0.05}) {
    const auto ggx = makeGgx(glm::dvec3(0.0), glm::dvec3(0.95), alpha);
    const shared::SliceLobe lobe = measureLobe(*ggx, 0.02);
    EXPECT_NEAR(lobe.median.x, 2.0 * std::atan(alpha), 0.1 * 2.0 * alpha) << "α " << alpha;
    EXPECT_NEAR(lobe.energy.r, 0.95, 0.05);
    for (int k = 1; k < 4; ++k) {
      EXPECT_GT(lobe.angle[k], lobe.angle[k - 1]) << "ring " << k;
      EXPECT_LT(lobe.level[k], lobe.level[k - 1]) << "a wider ring reads a coarser level";
    }
    EXPECT_LT(lobe.angle[1], lobe.median.x);
    EXPECT_GT(lobe.angle[2], lobe.median.x);
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
  for (int k = 0; k < 4; ++k) {
    wide.angle[k] = 0.3f * static_cast<float>(k + 1);
    wide.level[k] = -1.0f;  // clamped to 0
  }
  const glm::vec3 mean = light.lobe(wide, {0, 1, 0}, {1, 0, 0}, {0, 0, 1});
  EXPECT_NEAR(mean.g, maps[1].integral() / (4.0 * kPi), 1e-4);

  std::array<SphereMap, 3> flat{SphereMap(5, 1.5f), SphereMap(5, 1.5f), SphereMap(5, 1.5f)};
  const PrefilteredLight constant = PrefilteredLight::build(flat);
  shared::SliceLobe narrow{};
  for (int k = 0; k < 4; ++k) {
    narrow.angle[k] = 0.01f * static_cast<float>(k + 1);
    narrow.level[k] = 4.3f - static_cast<float>(k);
  }
  const glm::vec3 d = glm::normalize(glm::vec3(0.3f, 0.5f, -0.8f));
  const glm::vec3 u = glm::normalize(glm::cross(d, glm::vec3(0, 1, 0)));
  EXPECT_NEAR(constant.lobe(narrow, d, u, glm::cross(d, u)).b, 1.5f, 1e-5f);
}

TEST(LobePath, ShareIsOneForNarrowLobesZeroForWideAndLinearBetween) {
  const float texel5 = shared::kPiF / 32.0f;
  EXPECT_EQ(shared::lobePathShare(0.4f * texel5, 5u), 1.0f);
  EXPECT_EQ(shared::lobePathShare(1.2f * texel5, 5u), 0.0f);
  EXPECT_NEAR(shared::lobePathShare(0.75f * texel5, 5u), 0.5f, 1e-6f);
  EXPECT_EQ(shared::lobePathShare(0.75f * texel5, 6u), 0.0f) << "a level finer resolves it";
}

TEST(LobePath, ShadesEnergyTimesTheLightWhereTheRaySeesAndNothingWhereNot) {
  std::array<SphereMap, 3> flat{SphereMap(5, 2.0f), SphereMap(5, 1.0f), SphereMap(5, 0.5f)};
  const PrefilteredLight light = PrefilteredLight::build(flat);
  const auto ggx = makeGgx(glm::dvec3(0.0), glm::dvec3(0.9, 0.7, 0.5), 0.02);
  const std::vector<shared::SliceLobe> lobes = measureLobes(*ggx, {0.3, 0.9});
  const LobePath path{&light, lobes, glm::mat3(1.0f), false};
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

TEST(Fused, KeepsTheSlicesEnergyWhereTheMapsDirectionsMissPartOfANarrowLobe) {
  // Under a uniform unit light with V = 1, a pixel is ∫ρ: exactly the
  // slice's energy, whatever the rotation. The map's directions alone
  // count a lobe about a texel wide as they happen to fall on it (the
  // rotated map's integral below: off by percents), which showed as rings.
  const auto ggx = makeGgx(glm::dvec3(0.0), glm::dvec3(0.9), 0.06);
  SliceTableOptions options;
  options.level = 4;
  options.thetaSamples = 4;
  const BrdfSliceTable table = BrdfSliceTable::build(*ggx, options);
  const PixelSlices slices = PixelSlices::synthesize(table);
  std::array<SphereMap, 3> unit{SphereMap(4, 1.0f), SphereMap(4, 1.0f), SphereMap(4, 1.0f)};
  for (auto& m : unit) m = m.weightedBySolidAngle();
  const FusedLight light = FusedLight::fromWeightedMaps(unit);
  VisibilityBits bits(4, 1);
  std::vector<std::uint32_t> ones(bits.wordsPerPoint(), ~0u);
  bits.assign(ones);
  const std::array<WeightedBits, 1> vis{WeightedBits{bits.point(0).data(), 1.0f}};
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

}  // namespace
}  // namespace haarcast
