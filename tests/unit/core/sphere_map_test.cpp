#include "haarcast/core/sphere_map.h"

#include <random>

#include <gtest/gtest.h>

namespace haarcast {
namespace {

TEST(SphereMap, PixelSolidAnglesSumToFourPi) {
  for (int level = 0; level <= 8; ++level) {
    double sum = 0.0;
    for (int row = 0; row < mapSize(level); ++row) sum += pixelSolidAngle(level, row) * mapSize(level);
    EXPECT_NEAR(sum, 4.0 * kPi, 1e-12) << "level " << level;
  }
}

TEST(SphereMap, DirectionConventionIsTheSeeds) {
  // (sin θ sin φ, cos θ, sin θ cos φ): θ from +Y, φ from +Z toward +X.
  const glm::dvec3 up = sphericalToDirection(0.0, 1.234);
  EXPECT_NEAR(up.y, 1.0, 1e-15);
  const glm::dvec3 z = sphericalToDirection(kPi / 2, 0.0);
  EXPECT_NEAR(z.z, 1.0, 1e-15);
  const glm::dvec3 x = sphericalToDirection(kPi / 2, kPi / 2);
  EXPECT_NEAR(x.x, 1.0, 1e-15);
}

TEST(SphereMap, SphericalRoundTrip) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 1000; ++k) {
    const double theta = 1e-3 + u(rng) * (kPi - 2e-3), phi = u(rng) * kTwoPi;
    const Spherical s = directionToSpherical(sphericalToDirection(theta, phi) * 3.0);
    EXPECT_NEAR(s.theta, theta, 1e-12);
    EXPECT_NEAR(std::remainder(s.phi - phi, kTwoPi), 0.0, 1e-12);
    EXPECT_GE(s.phi, 0.0);
    EXPECT_LT(s.phi, kTwoPi);
  }
}

TEST(SphereMap, BilinearIsExactAtCentresWrapsInPhiAndClampsAtPoles) {
  SphereMap m(3);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (float& v : m.values()) v = u(rng);
  for (int i = 0; i < m.size(); ++i)
    for (int j = 0; j < m.size(); ++j)
      EXPECT_NEAR(m.sampleBilinear(rowTheta(3, i), colPhi(3, j)), m.at(i, j), 1e-6);
  // Half-way between the last and first column is their mean (φ wraps).
  EXPECT_NEAR(m.sampleBilinear(rowTheta(3, 2), 0.0), 0.5 * (m.at(2, 7) + m.at(2, 0)), 1e-6);
  // Above the first row's centre θ is clamped to it.
  EXPECT_NEAR(m.sampleBilinear(0.0, colPhi(3, 4)), m.at(0, 4), 1e-6);
  EXPECT_NEAR(m.sampleBilinear(kPi, colPhi(3, 1)), m.at(7, 1), 1e-6);
}

TEST(SphereMap, IntegralConvergesToAnalytic) {
  // ∫ y² dω = 4π/3; the midpoint rule on rows converges at second order.
  double previous = 1e9;
  for (int level = 3; level <= 7; ++level) {
    const SphereMap m = SphereMap::fromFunction(level, [](const glm::dvec3& d) { return d.y * d.y; });
    const double error = std::abs(m.integral() - 4.0 * kPi / 3.0);
    EXPECT_LT(error, previous / 3.0) << "level " << level;
    previous = error;
  }
  EXPECT_LT(previous, 1e-3);
}

TEST(SphereMap, WeightedBySolidAngleSumsToIntegral) {
  const SphereMap m = SphereMap::fromFunction(4, [](const glm::dvec3& d) { return 1.0 + d.x + 2.0 * d.z * d.z; });
  const SphereMap weighted = m.weightedBySolidAngle();
  double sum = 0.0;
  for (float v : weighted.values()) sum += v;
  EXPECT_NEAR(sum, m.integral(), 1e-5);
}

TEST(SphereMap, AbsurdLevelsAreRefusedByName) {
  EXPECT_THROW(SphereMap(13), std::invalid_argument);
  EXPECT_THROW(SphereMap(-1), std::invalid_argument);
  try {
    checkLevel(40, "request");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("request: map level 40"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace haarcast
