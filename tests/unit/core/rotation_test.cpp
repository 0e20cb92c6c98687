// Properties every rotation method must have, and the rotation conventions.
#include "haarcast/core/rotation.h"

#include <random>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "test_maps.h"

#include "haarcast/core/brdf_slices.h"

namespace haarcast {
namespace {

using testing::maxAbs;
using testing::maxAbsDifference;

// A glossy lobe about a tilted axis: sharp enough to expose interpolation.
HaarMap lobeMap(int level, double exponent) {
  const glm::dvec3 axis = glm::normalize(glm::dvec3(0.3, 0.8, 0.5));
  return forwardHaar(supersampledMap(level, 2, [&](const glm::dvec3& d) {
    return std::pow(std::max(0.0, glm::dot(d, axis)), exponent);
  }));
}

TEST(Rotation, MatrixConventions) {
  // R_y(a) adds a to φ.
  const glm::dvec3 d = rotationMatrix({0.7, 0.0, 0.0}) * sphericalToDirection(1.1, 0.4);
  const Spherical s = directionToSpherical(d);
  EXPECT_NEAR(s.theta, 1.1, 1e-12);
  EXPECT_NEAR(s.phi, 1.1, 1e-12);
  // R_x(b) tilts +Y toward +Z.
  const glm::dvec3 y = rotationMatrix({0.0, 0.3, 0.0}) * glm::dvec3(0, 1, 0);
  EXPECT_NEAR(y.y, std::cos(0.3), 1e-12);
  EXPECT_NEAR(y.z, std::sin(0.3), 1e-12);
  // The normal of a slice rotated by (α, β, γ) points at elevation β, azimuth α.
  const Spherical n = directionToSpherical(rotationMatrix({2.0, 0.9, 1.3}) * glm::dvec3(0, 1, 0));
  EXPECT_NEAR(n.theta, 0.9, 1e-12);
  EXPECT_NEAR(n.phi, 2.0, 1e-12);
}

TEST(Rotation, EulerRoundTrip) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<EulerYXY> cases = {{0.4, 0.0, 0.3}, {1.0, kPi, 0.5}, {0, 0, 0}};
  for (int k = 0; k < 200; ++k) cases.push_back({u(rng) * 8 - 4, u(rng) * 8 - 4, u(rng) * 8 - 4});
  for (const EulerYXY& e : cases) {
    const glm::dmat3 m = rotationMatrix(e);
    const EulerYXY back = eulerFromMatrix(m);
    EXPECT_GE(back.beta, 0.0);
    EXPECT_LE(back.beta, kPi);
    const glm::dmat3 m2 = rotationMatrix(back);
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r) ASSERT_NEAR(m2[c][r], m[c][r], 1e-9) << e.alpha << " " << e.beta << " " << e.gamma;
  }
}

TEST(Rotation, MethodNamesAreTheDesignNames) {
  const char* names[] = {"fused", "haar", "spatial", "matrix", "table", "splitsum"};
  for (const char* n : names) {
    const auto m = parseRotationMethod(n);
    ASSERT_TRUE(m.has_value()) << n;
    EXPECT_EQ(methodName(*m), n);
  }
  // Every method a renderer takes has its name, and the list says them all.
  for (const RotationMethod m : kAllPixelMethods) EXPECT_EQ(parseRotationMethod(methodName(m)), m) << methodName(m);
  EXPECT_EQ(pixelMethodNames(), "fused, haar, spatial, matrix, table, splitsum");
  EXPECT_FALSE(parseRotationMethod("Haar").has_value());
  EXPECT_FALSE(parseRotationMethod("").has_value());
  EXPECT_EQ(parseHaarVariant("faithful"), HaarVariant::Faithful);
  EXPECT_EQ(parseHaarVariant("local"), HaarVariant::Local);
  EXPECT_EQ(parseHaarVariant("refined"), HaarVariant::Refined);
  EXPECT_FALSE(parseHaarVariant("best").has_value());
}

TEST(Rotation, SpatialMovesWhatIsAtDToRd) {
  // g(ω) = f(Rᵀω): the peak of a lobe about axis a ends up about R·a.
  const int level = 6;
  const glm::dvec3 axis = glm::normalize(glm::dvec3(0.3, 0.8, 0.5));
  const EulerYXY r{1.0, 0.8, -0.4};
  const SphereMap g = inverseHaar(rotateSpatial(lobeMap(level, 200.0), r));
  int bi = 0, bj = 0;
  for (int i = 0; i < g.size(); ++i)
    for (int j = 0; j < g.size(); ++j)
      if (g.at(i, j) > g.at(bi, bj)) bi = i, bj = j;
  const glm::dvec3 peak = sphericalToDirection(rowTheta(level, bi), colPhi(level, bj));
  EXPECT_GT(glm::dot(peak, rotationMatrix(r) * axis), std::cos(2.0 * kPi / 64.0));
}

TEST(Rotation, SpatialConvergesToTheAnalyticRotation) {
  // A smooth function: away from the clamped polar caps the bilinear
  // resampler is second order, so the solid-angle RMS error against the
  // analytic rotation falls by well over 2× per level.
  const auto f = [](const glm::dvec3& d) { return 1.0 + d.x * d.y + 0.5 * d.z * d.z * d.z + 0.3 * d.y; };
  const EulerYXY r{0.5, 1.1, 2.0};
  const glm::dmat3 rt = glm::transpose(rotationMatrix(r));
  double previous = 1e9;
  for (int level = 3; level <= 7; ++level) {
    const SphereMap g = rotateSpatialMap(SphereMap::fromFunction(level, f), r);
    const SphereMap exact = SphereMap::fromFunction(level, [&](const glm::dvec3& d) { return f(rt * d); });
    double se = 0.0;
    for (int i = 0; i < g.size(); ++i)
      for (int j = 0; j < g.size(); ++j) se += std::pow(g.at(i, j) - exact.at(i, j), 2) * pixelSolidAngle(level, i);
    const double rms = std::sqrt(se / (4.0 * kPi));
    EXPECT_LT(rms, previous / 2.5) << "level " << level;
    previous = rms;
  }
  EXPECT_LT(previous, 1e-3);
}

class EveryMethod : public ::testing::TestWithParam<RotationMethod> {};

TEST_P(EveryMethod, ZeroRotationIsTheIdentity) {
  const int level = 4;
  std::vector<HaarMap> slices = {lobeMap(level, 8.0), lobeMap(level, 64.0)};
  const auto rotator = makeRotator(GetParam(), slices);
  for (std::size_t s = 0; s < slices.size(); ++s) {
    HaarMap out;
    rotator->rotate(s, {}, out);
    EXPECT_LT(maxAbsDifference(out, slices[s]), 1e-5 * maxAbs(slices[s])) << methodName(GetParam());
  }
}

TEST_P(EveryMethod, WholePixelPhiShiftsAreExact) {
  const int level = 4;
  const int m = mapSize(level);
  const std::vector<HaarMap> slices = {lobeMap(level, 64.0)};
  const auto rotator = makeRotator(GetParam(), slices);
  const SphereMap f = inverseHaar(slices[0]);
  for (int shiftA : {0, 1, 5}) {
    for (int shiftG : {0, 2, 3}) {
      const double px = kTwoPi / m;
      HaarMap out;
      rotator->rotate(0, {shiftA * px, 0.0, shiftG * px}, out);
      // g(φ) = f(φ − shift): a permutation of the columns.
      SphereMap expected(level);
      for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) expected.at(i, j) = f.at(i, ((j - shiftA - shiftG) % m + m) % m);
      EXPECT_LT(maxAbsDifference(out, forwardHaar(expected)), 1e-5 * maxAbs(slices[0]))
          << methodName(GetParam()) << " shift " << shiftA << "+" << shiftG;
    }
  }
}

TEST_P(EveryMethod, StoresAtLeastTheUnrotatedSlices) {
  const std::vector<HaarMap> slices = {lobeMap(4, 8.0), lobeMap(4, 64.0)};
  const auto rotator = makeRotator(GetParam(), slices);
  EXPECT_GE(rotator->storedBytes(), 2 * 256 * sizeof(float));
  EXPECT_EQ(rotator->sliceCount(), 2u);
  EXPECT_EQ(rotator->level(), 4);
  EXPECT_EQ(rotator->method(), GetParam());
}

INSTANTIATE_TEST_SUITE_P(Rotation, EveryMethod, ::testing::ValuesIn(kAllRotationMethods),
                         [](const ::testing::TestParamInfo<RotationMethod>& p) { return std::string(methodName(p.param)); });

TEST(Rotation, MakeRotatorRefusesEmptyOrMixedSlices) {
  EXPECT_THROW(makeRotator(RotationMethod::Haar, {}), std::invalid_argument);
  EXPECT_THROW(makeRotator(RotationMethod::Spatial, {HaarMap(3), HaarMap(4)}), std::invalid_argument);
}

}  // namespace
}  // namespace haarcast
