#include "haarcast/core/triple_product.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "haarcast/core/haar.h"
#include "haarcast/core/sphere_map.h"
#include "test_maps.h"

namespace haarcast {
namespace {

using testing::randomBinaryMap;
using testing::randomMap;

// float storage of maps and coefficients bounds the agreement.
constexpr double kRelativeTolerance = 1e-5;

// The triple product directly on pixels, and Σ|·| to scale the tolerance by.
struct PixelSum {
  double value = 0.0;
  double magnitude = 0.0;
};

PixelSum pixelTripleProduct(const SphereMap& weightedLight, const SphereMap& brdf, const SphereMap& visibility) {
  PixelSum s;
  for (std::size_t p = 0; p < weightedLight.pixelCount(); ++p) {
    const double term = static_cast<double>(weightedLight.values()[p]) * brdf.values()[p] * visibility.values()[p];
    s.value += term;
    s.magnitude += std::abs(term);
  }
  return s;
}

SparseHaar unitCoefficient(int level, std::size_t index) {
  SparseHaar s;
  s.level = level;
  s.index = {static_cast<std::uint32_t>(index)};
  s.value = {1.0f};
  return s;
}

// Every Haar triple at small levels: tripleProduct on one-hot coefficient
// vectors must equal Σ_p ψ_i ψ_j ψ_k of the reconstructed basis functions, so
// each tripling coefficient (scaling, same-type, all-types, zero) is checked.
TEST(TripleProduct, EveryTriplingCoefficientMatchesPixelSum) {
  for (int level = 0; level <= 3; ++level) {
    SCOPED_TRACE(level);
    HaarMap probe(level);
    const std::size_t count = probe.coefficientCount();
    std::vector<SphereMap> basis;
    for (std::size_t i = 0; i < count; ++i) {
      HaarMap unit(level);
      unit[i] = 1.0f;
      basis.push_back(inverseHaar(unit));
    }
    int nonZero = 0;
    for (std::size_t i = 0; i < count; ++i) {
      for (std::size_t j = 0; j < count; ++j) {
        HaarMap brdf(level);
        brdf[j] = 1.0f;
        for (std::size_t k = 0; k < count; ++k) {
          const double expected = pixelTripleProduct(basis[i], basis[j], basis[k]).value;
          const double got = tripleProduct(unitCoefficient(level, i), brdf, unitCoefficient(level, k));
          ASSERT_NEAR(got, expected, 1e-6) << "i=" << i << " j=" << j << " k=" << k;
          if (expected != 0.0) ++nonZero;
        }
      }
    }
    // The sparsity the tripling theorem predicts: the test is not vacuous.
    EXPECT_GT(nonZero, 0);
  }
}

TEST(TripleProduct, FullLightMatchesPixelSumAtLevels0To6) {
  std::mt19937 rng(7);
  double worst = 0.0;
  for (int level = 0; level <= 6; ++level) {
    SCOPED_TRACE(level);
    const SphereMap light = randomMap(level, 0.0, 2.0, rng).weightedBySolidAngle();
    const SphereMap brdf = randomMap(level, 0.0, 3.0, rng);
    const SphereMap visibility = randomBinaryMap(level, rng);
    const PixelSum expected = pixelTripleProduct(light, brdf, visibility);
    const double got = tripleProduct(SparseHaar::fromDense(forwardHaar(light)), forwardHaar(brdf),
                                     SparseHaar::fromDense(forwardHaar(visibility)));
    EXPECT_NEAR(got, expected.value, kRelativeTolerance * expected.magnitude);
    worst = std::max(worst, std::abs(got - expected.value) / expected.magnitude);
  }
  RecordProperty("max_relative_error", (::testing::Message() << worst).GetString());
}

// Zero-mean maps: the scaling term no longer dominates, so the detail terms
// (and their signs) carry the whole sum.
TEST(TripleProduct, SignedMapsMatchPixelSum) {
  std::mt19937 rng(11);
  for (int level = 1; level <= 6; ++level) {
    SCOPED_TRACE(level);
    const SphereMap light = randomMap(level, -1.0, 1.0, rng);
    const SphereMap brdf = randomMap(level, -1.0, 1.0, rng);
    const SphereMap visibility = randomMap(level, -1.0, 1.0, rng);
    const PixelSum expected = pixelTripleProduct(light, brdf, visibility);
    const double got = tripleProduct(SparseHaar::fromDense(forwardHaar(light)), forwardHaar(brdf),
                                     SparseHaar::fromDense(forwardHaar(visibility)));
    EXPECT_NEAR(got, expected.value, kRelativeTolerance * expected.magnitude);
  }
}

// Non-linear approximation of light and visibility: the sum must equal the
// pixel sum of the truncated functions reconstructed, whichever blocks each
// keeps (blocks present in one only, in both, or in neither).
TEST(TripleProduct, TruncatedLightAndVisibilityMatchPixelSum) {
  std::mt19937 rng(3);
  double worst = 0.0;
  for (int level = 1; level <= 6; ++level) {
    SCOPED_TRACE(level);
    const SphereMap light = randomMap(level, 0.0, 5.0, rng).weightedBySolidAngle();
    const SphereMap brdf = randomMap(level, 0.0, 1.0, rng);
    const SphereMap visibility = randomBinaryMap(level, rng);
    const HaarMap lightCoeffs = forwardHaar(light);
    const HaarMap brdfCoeffs = forwardHaar(brdf);
    const HaarMap visibilityCoeffs = forwardHaar(visibility);
    for (const std::size_t kLight : {1u, 2u, 4u, 16u, 64u, 256u, 4096u}) {
      for (const std::size_t kVisibility : {1u, 3u, 8u, 32u, 128u}) {
        SCOPED_TRACE(::testing::Message() << "kLight=" << kLight << " kVisibility=" << kVisibility);
        const SparseHaar lightK = keepLargest(lightCoeffs, kLight);
        const SparseHaar visibilityK = keepLargest(visibilityCoeffs, kVisibility);
        const PixelSum expected =
            pixelTripleProduct(inverseHaar(lightK.toDense()), brdf, inverseHaar(visibilityK.toDense()));
        const double got = tripleProduct(lightK, brdfCoeffs, visibilityK);
        EXPECT_NEAR(got, expected.value, kRelativeTolerance * expected.magnitude);
        EXPECT_NEAR(tripleProductBruteForce(lightK.toDense(), brdfCoeffs, visibilityK.toDense()), expected.value,
                    kRelativeTolerance * expected.magnitude);
        worst = std::max(worst, std::abs(got - expected.value) / expected.magnitude);
      }
    }
  }
  RecordProperty("max_relative_error", (::testing::Message() << worst).GetString());
}

// Empty sparse inputs are zero functions.
TEST(TripleProduct, EmptyLightOrVisibilityGivesZero) {
  std::mt19937 rng(5);
  const HaarMap brdf = forwardHaar(randomMap(4, 0.0, 1.0, rng));
  const SparseHaar full = SparseHaar::fromDense(forwardHaar(randomMap(4, 0.0, 1.0, rng)));
  SparseHaar empty;
  empty.level = 4;
  EXPECT_EQ(tripleProduct(empty, brdf, full), 0.0);
  EXPECT_EQ(tripleProduct(full, brdf, empty), 0.0);
}

// L constant: Σ (L·ΔΩ)·ρ·V = L·∫ρ·V dω.
TEST(TripleProduct, ConstantLightIntegratesBrdfTimesVisibility) {
  std::mt19937 rng(9);
  for (int level = 1; level <= 6; ++level) {
    SCOPED_TRACE(level);
    constexpr double kRadiance = 1.5;
    const SphereMap light = SphereMap(level, static_cast<float>(kRadiance)).weightedBySolidAngle();
    const SphereMap brdf = randomMap(level, 0.0, 2.0, rng);
    const SphereMap visibility = randomBinaryMap(level, rng);
    SphereMap product(level);
    for (std::size_t p = 0; p < product.pixelCount(); ++p) {
      product.values()[p] = brdf.values()[p] * visibility.values()[p];
    }
    const double expected = kRadiance * product.integral();
    const double got = tripleProduct(SparseHaar::fromDense(forwardHaar(light)), forwardHaar(brdf),
                                     SparseHaar::fromDense(forwardHaar(visibility)));
    EXPECT_NEAR(got, expected, kRelativeTolerance * std::abs(expected));
  }
}

TEST(TripleProduct, LevelMismatchThrows) {
  const SparseHaar level3 = SparseHaar::fromDense(forwardHaar(SphereMap(3, 1.0f)));
  const SparseHaar level4 = SparseHaar::fromDense(forwardHaar(SphereMap(4, 1.0f)));
  const HaarMap brdf4 = forwardHaar(SphereMap(4, 1.0f));
  EXPECT_THROW(tripleProduct(level3, brdf4, level4), std::invalid_argument);
  EXPECT_THROW(tripleProduct(level4, brdf4, level3), std::invalid_argument);
  EXPECT_THROW(tripleProductBruteForce(level3.toDense(), brdf4, level4.toDense()), std::invalid_argument);
  EXPECT_NO_THROW(tripleProduct(level4, brdf4, level4));
}

TEST(TripleProduct, IndexOutsideMapThrows) {
  const HaarMap brdf = forwardHaar(SphereMap(2, 1.0f));
  const SparseHaar inside = SparseHaar::fromDense(brdf);
  SparseHaar outside = unitCoefficient(2, 16);
  EXPECT_THROW(tripleProduct(outside, brdf, inside), std::invalid_argument);
  EXPECT_THROW(tripleProduct(inside, brdf, outside), std::invalid_argument);
}

}  // namespace
}  // namespace haarcast
