// `splitsum` (core/splitsum.h): the lobe's energy times the prefiltered
// light along the mirror direction, at the level of the lobe's width.
#include "haarcast/core/splitsum.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>

#include "haarcast/core/brdf.h"
#include "haarcast/core/lobe.h"
#include "haarcast/core/prefiltered_light.h"
#include "haarcast/core/sphere_map.h"

namespace haarcast {
namespace {

TEST(Splitsum, UnderAUniformWhiteLightAPixelIsTheLobesEnergy) {
  // L = 1 everywhere: every level of the prefiltered light is 1, so the
  // pixel is exactly E_c(θₒ), whatever the rotation, θₒ or lobe width; and
  // black where its mirror ray is blocked.
  const std::array<SphereMap, 3> white{SphereMap(6, 1.0f), SphereMap(6, 1.0f), SphereMap(6, 1.0f)};
  const PrefilteredLight light = PrefilteredLight::build(white);
  for (const auto& brdf : {makeGgx(glm::dvec3(0.0), glm::dvec3(0.9, 0.7, 0.5), 0.02),
                           makeGgx(glm::dvec3(0.1), glm::dvec3(0.9, 0.6, 0.5), 0.3), makeLambert(glm::dvec3(0.8, 0.5, 0.2))}) {
    const std::vector<shared::SliceLobe> lobes = measureLobes(*brdf, lobeThetaOut(8));
    const glm::mat3 toLight = glm::mat3(rotationMatrix({0.3, 1.2, -0.4}));
    const LobePath path{&light, lobes, toLight};
    for (const EulerYXY& r : randomRotations(6, 11)) {
      for (const double thetaOut : {0.0, 0.4, 1.0, 1.5}) {
        const shared::SliceBlend blend = shared::sliceBlendAt(static_cast<float>(thetaOut), 8u, 1u);
        const shared::SliceLobe lobe = shared::blendLobes(lobes[blend.first], lobes[blend.second], blend.weight);
        const std::array<float, 3> seen = splitsumShade(path, blend, r, thetaOut, shared::kLobeSeenBit | 5u);
        const std::array<float, 3> hidden = splitsumShade(path, blend, r, thetaOut, 5u);
        for (std::size_t c = 0; c < 3; ++c) {
          EXPECT_EQ(seen[c], lobe.energy[static_cast<int>(c)]) << "θₒ " << thetaOut << " channel " << c;
          EXPECT_EQ(hidden[c], 0.0f);
        }
      }
    }
  }
}

TEST(Splitsum, TheLevelsTexelHasTheDiscOfTheMedianAngle) {
  // A level-λ texel at the equator is (π/M)·(2π/M), M = 2^λ: 2π²/4^λ = π·a².
  float previous = 100.0f;
  for (const float a : {0.005f, 0.04f, 0.3f, 1.0f}) {
    const float level = shared::splitsumLevel(a);
    EXPECT_NEAR(2.0 * kPi * kPi / std::pow(4.0, level), kPi * a * a, 1e-4 * kPi * a * a) << "median angle " << a;
    EXPECT_LT(level, previous) << "a wider lobe reads a coarser level";
    previous = level;
  }
  EXPECT_TRUE(std::isfinite(shared::splitsumLevel(0.0f)));
}

TEST(Splitsum, UnderOneBrightTexelItIsTheEnergyTimesThePrefilteredLightAtTheMirrorDirection) {
  // One texel of the finest map lit, the one the pixel's mirror direction
  // falls in (or a neighbour): what the pixel reads is the prefiltered light
  // (lobe_test.cpp checks its levels) at the lobe's level, along the mirror
  // direction computed here in double.
  const auto ggx = makeGgx(glm::dvec3(0.0), glm::dvec3(0.9, 0.7, 0.5), 0.05);
  const std::vector<shared::SliceLobe> lobes = measureLobes(*ggx, lobeThetaOut(4));
  const glm::mat3 toLight = glm::mat3(rotationMatrix({-0.6, 0.9, 0.2}));
  for (const EulerYXY& r : randomRotations(5, 23)) {
    for (const double thetaOut : {0.2, 0.9, 1.3}) {
      const glm::dvec3 mirror = glm::dvec3(splitsumMirror(toLight, r, thetaOut));
      const glm::dvec3 expected = glm::dmat3(toLight) * rotationMatrix(r) *
                                  glm::dvec3(0.0, std::cos(thetaOut), -std::sin(thetaOut));
      ASSERT_NEAR(glm::length(mirror - expected), 0.0, 1e-6);
      const Spherical s = directionToSpherical(mirror);
      const int n = 7, m = mapSize(n);
      const int row = std::clamp(static_cast<int>(s.theta / kPi * m), 0, m - 1);
      const int col = static_cast<int>(std::fmod(s.phi + 2.0 * kPi, 2.0 * kPi) / (2.0 * kPi) * m) % m;
      for (const int dc : {0, 1}) {
        std::array<SphereMap, 3> maps{SphereMap(n), SphereMap(n), SphereMap(n)};
        for (int c = 0; c < 3; ++c) maps[static_cast<std::size_t>(c)].at(row, (col + dc) % m) = 1000.0f * static_cast<float>(c + 1);
        const PrefilteredLight light = PrefilteredLight::build(maps);
        const LobePath path{&light, lobes, toLight};
        const shared::SliceBlend blend = shared::sliceBlendAt(static_cast<float>(thetaOut), 4u, 1u);
        const shared::SliceLobe lobe = shared::blendLobes(lobes[blend.first], lobes[blend.second], blend.weight);
        const double lambda = shared::splitsumLevel(lobe.median.x);
        const std::array<float, 3> got = splitsumShade(path, blend, r, thetaOut, shared::kLobeSeenBit);
        for (int c = 0; c < 3; ++c) {
          const double want = lobe.energy[c] * light.sample(static_cast<float>(lambda), glm::vec3(expected))[c];
          EXPECT_GT(want, 0.0) << "the lit texel is under the lookup";
          EXPECT_NEAR(got[static_cast<std::size_t>(c)], want, 2e-4 * want + 1e-4)
              << "θₒ " << thetaOut << " λ " << lambda << " channel " << c << " column offset " << dc;
        }
      }
    }
  }
}

TEST(Splitsum, KeepsOnlyItsLobes) {
  EXPECT_EQ(splitsumStoredBytes(16), 16 * sizeof(shared::SliceLobe));
  const std::vector<double> t = lobeThetaOut(4);
  ASSERT_EQ(t.size(), 4u);
  for (std::size_t i = 0; i < t.size(); ++i) EXPECT_DOUBLE_EQ(t[i], (static_cast<double>(i) + 0.5) * (kPi / 2.0) / 4.0);
  EXPECT_THROW(lobeThetaOut(0), std::invalid_argument);
  EXPECT_THROW(makeRotator(RotationMethod::Splitsum, {HaarMap(2)}), std::invalid_argument);
}

}  // namespace
}  // namespace haarcast
