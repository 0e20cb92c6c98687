// The seed's method: `refined` must equal `spatial`; `faithful` is held to
// floors measured on this code (see the comments at each floor).
#include "haarcast/core/rotate_haar.h"

#include <random>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "test_maps.h"

#include "haarcast/assets/procedural_environment.h"
#include "haarcast/core/brdf.h"
#include "haarcast/core/brdf_slices.h"
#include "haarcast/core/metrics.h"

namespace haarcast {
namespace {

using testing::maxAbs;
using testing::maxAbsDifference;

HaarMap phongSlice(int level, double exponent, double thetaOut) {
  const auto brdf = makePhong(glm::dvec3(0.0), glm::dvec3(1.0), exponent);
  return forwardHaar(sliceMap(*brdf, thetaOut, 0, level, 2));
}

TEST(RotateHaar, IntegralFromCoefficientsMatchesThePixels) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int level = 0; level <= 6; ++level) {
    SphereMap m(level);
    for (float& v : m.values()) v = u(rng);
    EXPECT_NEAR(integralFromCoefficients(forwardHaar(m)), m.integral(), 1e-5 * m.integral()) << level;
  }
}

TEST(RotateHaar, RefinedEqualsSpatial) {
  // Refined is the chain rule in exact finite form for the bilinear model
  // that `spatial` resamples with: equal up to float rounding.
  for (int level = 1; level <= 6; ++level) {
    for (double exponent : {1.0, 64.0, 512.0}) {
      const HaarMap f = phongSlice(level, exponent, 0.6);
      for (const EulerYXY& r : randomRotations(level <= 4 ? 12 : 4, 100u + static_cast<unsigned>(level))) {
        const HaarMap h = rotateHaar(f, r);
        const HaarMap s = rotateSpatial(f, r);
        ASSERT_LT(maxAbsDifference(h, s), 2e-5 * maxAbs(s))
            << "level " << level << " exponent " << exponent << " rotation " << r.alpha << "," << r.beta << "," << r.gamma;
      }
    }
  }
}

TEST(RotateHaar, RefinedHandlesEveryPoleAndSeamCase) {
  // Rotations that put the source poles and the φ seam under g's pixels. At
  // level 7 a step near a source pole crosses up to 64 columns.
  for (int level : {5, 7}) {
    const HaarMap f = phongSlice(level, 64.0, 0.0);
    for (const EulerYXY& r : {EulerYXY{0, kPi, 0}, EulerYXY{0, kPi / 2, 0}, EulerYXY{kPi, 1e-9, 0},
                              EulerYXY{0.001, kPi - 0.01, -0.001}, EulerYXY{3.0, 0.02, 1.0}}) {
      EXPECT_LT(maxAbsDifference(rotateHaar(f, r), rotateSpatial(f, r)), 2e-5 * maxAbs(f))
          << "level " << level << " beta " << r.beta;
    }
  }
}

TEST(RotateHaar, CoarserStartLevelRotatesTheLowPass) {
  // Starting k levels coarser = rotating the level-(n−k) map of f's coarse
  // coefficients, with no finer details in the result (seed: O(N/4^k)).
  const int n = 6;
  const HaarMap f = phongSlice(n, 16.0, 0.4);
  for (int start : {2, 3, 4}) {
    const int w = start + 1;
    const double scale = static_cast<double>(1 << (n - w));
    HaarMap low(w);
    for (int r = 0; r < (1 << w); ++r)
      for (int c = 0; c < (1 << w); ++c)
        low[static_cast<std::size_t>(r * (1 << w) + c)] = static_cast<float>(f[static_cast<std::size_t>(r * (1 << n) + c)] / scale);
    for (const EulerYXY& r : randomRotations(3, 7)) {
      const HaarMap g = rotateHaar(f, r, {HaarVariant::Refined, start});
      const HaarMap expected = rotateSpatial(low, r);
      for (int row = 0; row < (1 << n); ++row)
        for (int col = 0; col < (1 << n); ++col) {
          const float got = g[static_cast<std::size_t>(row * (1 << n) + col)];
          if (row < (1 << w) && col < (1 << w)) {
            ASSERT_NEAR(got, expected[static_cast<std::size_t>(row * (1 << w) + col)] * scale, 2e-5 * maxAbs(f));
          } else {
            ASSERT_EQ(got, 0.0f) << "detail finer than the start level at " << row << "," << col;
          }
        }
    }
  }
}

TEST(RotateHaar, BadStartLevelIsRefused) {
  const HaarMap f = phongSlice(4, 4.0, 0.2);
  EXPECT_THROW(rotateHaar(f, {}, {HaarVariant::Refined, 4}), std::invalid_argument);
  RotatorOptions o;
  o.haarStartLevel = 9;
  EXPECT_THROW(makeRotator(RotationMethod::Haar, {f}, o), std::invalid_argument);
}

TEST(RotateHaar, LevelZeroMapIsRotationInvariant) {
  HaarMap f(0);
  f[0] = 3.0f;
  EXPECT_EQ(rotateHaar(f, {1, 2, 3})[0], 3.0f);
}

// Render PSNR of a variant against spatial: Σ over rotations of the integral
// of the rotated slice against the procedural HDR environment (sun included).
double renderPsnrVsSpatial(HaarVariant variant, int level, double exponent) {
  const auto env = assets::proceduralEnvironment(level, 4);
  const HaarMap light = forwardHaar(env[0].weightedBySolidAngle());
  const HaarMap f = phongSlice(level, exponent, 0.6);
  std::vector<double> ref, test;
  for (const EulerYXY& r : randomRotations(64, 1)) {
    const HaarMap s = rotateSpatial(f, r), h = rotateHaar(f, r, {variant, -1});
    double vs = 0.0, vh = 0.0;
    for (std::size_t i = 0; i < f.coefficientCount(); ++i) {
      vs += static_cast<double>(s[i]) * light[i];  // V = 1: the triple product is this inner product
      vh += static_cast<double>(h[i]) * light[i];
    }
    ref.push_back(vs);
    test.push_back(vh);
  }
  return compareSignals(ref, test).psnr;
}

TEST(RotateHaar, OneLevelVariantsMeetTheirMeasuredFloors) {
  // Measured on this code (64 rotations, seed 1, level 5): faithful 48.8 dB
  // (Lambert) and 29.8 dB (Phong-64); local 39.0 and 15.9 dB. The glossy
  // figures depend strongly on the rotation set (faithful 8.5–35 dB over
  // seeds 1–8): the one-level variants fail badly on some rotations, and the
  // peak depends on whether a rotation catches the sun. The floors sit ~3 dB
  // below the values for this fixed list, so a regression of either path
  // fails here; see docs/design.md, "What limits the accuracy".
  struct Case {
    HaarVariant variant;
    double exponent;
    double floor;
  };
  for (const Case& c : {Case{HaarVariant::Faithful, 1.0, 45.0}, Case{HaarVariant::Faithful, 64.0, 26.0},
                        Case{HaarVariant::Local, 1.0, 36.0}, Case{HaarVariant::Local, 64.0, 12.0}}) {
    const double psnr = renderPsnrVsSpatial(c.variant, 5, c.exponent);
    RecordProperty(std::string(variantName(c.variant)) + "_exp" + std::to_string(static_cast<int>(c.exponent)),
                   std::to_string(psnr));
    EXPECT_GT(psnr, c.floor) << variantName(c.variant) << " exponent " << c.exponent;
  }
}

TEST(RotateHaar, OneLevelVariantsConvergeForSmoothMaps) {
  // Both estimate what one level does not say; on a smooth map the estimate
  // improves with the level, so the error against spatial falls every level.
  const auto fn = [](const glm::dvec3& d) { return 1.0 + 0.5 * d.y + 0.3 * d.x + 0.2 * d.z * d.x; };
  for (HaarVariant v : {HaarVariant::Faithful, HaarVariant::Local}) {
    for (const EulerYXY& r : {EulerYXY{}, EulerYXY{0.3, 0.7, 0.2}}) {
      double previous = 1e9;
      for (int level = 4; level <= 7; ++level) {
        const HaarMap f = forwardHaar(SphereMap::fromFunction(level, fn));
        const double err = maxAbsDifference(rotateHaar(f, r, {v, -1}), rotateSpatial(f, r)) / maxAbs(f);
        EXPECT_LT(err, previous / 1.6) << variantName(v) << " level " << level;
        previous = err;
      }
    }
  }
}

}  // namespace
}  // namespace haarcast
