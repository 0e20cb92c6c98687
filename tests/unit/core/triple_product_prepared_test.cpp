// The per-pixel triple product: prepared light and visibility must give what
// tripleProduct and the brute force give, and the merged visibility what the
// barycentric sum of three products gives.
#include <array>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "../allocation_tracking.h"

#include "haarcast/core/haar.h"
#include "haarcast/core/sphere_map.h"
#include "haarcast/core/triple_product.h"
#include "test_maps.h"

namespace haarcast {
namespace {

using testing::randomBinaryMap;
using testing::randomMap;

// A random subset of a dense map's coefficients (the scaling one included or
// not): blocks with one, two or three bands, in light only, visibility only
// or both.
SparseHaar randomSubset(const HaarMap& dense, double keep, std::mt19937& rng) {
  std::bernoulli_distribution take(keep);
  SparseHaar s;
  s.level = dense.level();
  for (std::size_t i = 0; i < dense.coefficientCount(); ++i) {
    if (!take(rng)) continue;
    s.index.push_back(static_cast<std::uint32_t>(i));
    s.value.push_back(dense[i]);
  }
  return s;
}

// Σ_p |L·ρ·V| over pixels: the scale of the sum's rounding.
double magnitude(const SparseHaar& light, const HaarMap& brdf, const SparseHaar& visibility) {
  const SphereMap l = inverseHaar(light.toDense()), b = inverseHaar(brdf), v = inverseHaar(visibility.toDense());
  double sum = 0.0;
  for (std::size_t p = 0; p < l.pixelCount(); ++p) sum += std::abs(static_cast<double>(l.values()[p]) * b.values()[p] * v.values()[p]);
  return sum;
}

struct Case {
  SparseHaar light;
  HaarMap brdf;
  SparseHaar visibility;
};

// Light truncated by keepLargest or thinned at random, a dense signed BRDF,
// visibility truncated or thinned: sparse inputs of every shape.
std::vector<Case> randomCases() {
  std::mt19937 rng(21);
  std::vector<Case> cases;
  for (int level = 0; level <= 6; ++level) {
    for (int variant = 0; variant < 4; ++variant) {
      const HaarMap light = forwardHaar(randomMap(level, 0.0, 4.0, rng).weightedBySolidAngle());
      const HaarMap brdf = forwardHaar(randomMap(level, -1.0, 2.0, rng));
      const HaarMap visibility = forwardHaar(randomBinaryMap(level, rng));
      Case c{{}, brdf, {}};
      const std::size_t k = std::size_t{1} << (2 * variant + 1);
      c.light = variant % 2 ? keepLargest(light, 32 * k) : randomSubset(light, 0.2 + 0.2 * variant, rng);
      c.visibility = variant % 2 ? randomSubset(visibility, 0.5, rng) : keepLargest(visibility, 4 * k);
      cases.push_back(std::move(c));
    }
  }
  return cases;
}

TEST(PreparedTripleProduct, EqualsTripleProductAndBruteForce) {
  TripleProductScratch scratch;
  PreparedVisibility visibility;
  for (const Case& c : randomCases()) {
    SCOPED_TRACE(::testing::Message() << "level " << c.brdf.level() << " kL " << c.light.size() << " kV " << c.visibility.size());
    const PreparedLight light(c.light);
    visibility.assign(c.visibility);
    const double scale = magnitude(c.light, c.brdf, c.visibility) + 1e-30;
    const double old = tripleProduct(c.light, c.brdf, c.visibility);
    const double prepared = tripleProduct(light, c.brdf, visibility);
    // tripleProduct prepares both operands per call and walks the same way;
    // the brute force is the independent reference.
    EXPECT_NEAR(prepared, old, 1e-12 * scale);
    EXPECT_NEAR(tripleProduct(light, c.brdf, c.visibility, scratch), old, 1e-12 * scale);
    EXPECT_NEAR(prepared, tripleProductBruteForce(c.light.toDense(), c.brdf, c.visibility.toDense()), 1e-5 * scale);
  }
}

TEST(PreparedTripleProduct, EveryTriplingCoefficientMatchesTripleProduct) {
  for (int level = 0; level <= 2; ++level) {
    HaarMap probe(level);
    const auto count = static_cast<std::uint32_t>(probe.coefficientCount());
    auto unit = [&](std::uint32_t i) { return SparseHaar{level, {i}, {1.0f}}; };
    for (std::uint32_t i = 0; i < count; ++i)
      for (std::uint32_t j = 0; j < count; ++j) {
        HaarMap brdf(level);
        brdf[j] = 1.0f;
        for (std::uint32_t k = 0; k < count; ++k) {
          ASSERT_DOUBLE_EQ(tripleProduct(PreparedLight(unit(i)), brdf, PreparedVisibility(unit(k))),
                           tripleProduct(unit(i), brdf, unit(k)))
              << "level " << level << " i=" << i << " j=" << j << " k=" << k;
        }
      }
  }
}

TEST(PreparedTripleProduct, DuplicateIndicesKeepTheLastValue) {
  std::mt19937 rng(4);
  const HaarMap brdf = forwardHaar(randomMap(3, 0.0, 1.0, rng));
  const SparseHaar visibility = SparseHaar::fromDense(forwardHaar(randomBinaryMap(3, rng)));
  const SparseHaar duplicated{3, {0, 9, 9, 17}, {1.0f, 5.0f, 2.0f, 0.5f}};
  const SparseHaar last{3, {0, 9, 17}, {1.0f, 2.0f, 0.5f}};
  EXPECT_DOUBLE_EQ(tripleProduct(PreparedLight(duplicated), brdf, PreparedVisibility(visibility)),
                   tripleProduct(last, brdf, visibility));
}

TEST(PreparedTripleProduct, BadOperandsAreRefused) {
  const HaarMap brdf4 = forwardHaar(SphereMap(4, 1.0f));
  const SparseHaar level3 = SparseHaar::fromDense(forwardHaar(SphereMap(3, 1.0f)));
  const SparseHaar level4 = SparseHaar::fromDense(brdf4);
  EXPECT_THROW(tripleProduct(PreparedLight(level3), brdf4, PreparedVisibility(level4)), std::invalid_argument);
  EXPECT_THROW(tripleProduct(PreparedLight(level4), brdf4, PreparedVisibility(level3)), std::invalid_argument);
  EXPECT_THROW(PreparedLight(SparseHaar{2, {16}, {1.0f}}), std::invalid_argument);
  EXPECT_THROW(PreparedLight(SparseHaar{2, {1, 2}, {1.0f}}), std::invalid_argument);
  EXPECT_THROW(PreparedLight(SparseHaar{kMaxLevel + 1, {}, {}}), std::invalid_argument);
  TripleProductScratch scratch;
  EXPECT_THROW(tripleProduct(PreparedLight(level4), brdf4, level3, scratch), std::invalid_argument);
}

// Per-vertex visibility as the renderer stores it: the 64 largest terms of a
// binary map, each vertex with its own occluders.
std::array<SparseHaar, 3> vertexVisibility(int level, std::mt19937& rng) {
  std::array<SparseHaar, 3> v;
  for (SparseHaar& x : v) x = keepLargest(forwardHaar(randomBinaryMap(level, rng)), 64);
  return v;
}

std::array<double, 3> randomBarycentrics(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double a = u(rng), b = u(rng);
  if (a + b > 1.0) {
    a = 1.0 - a;
    b = 1.0 - b;
  }
  return {a, b, 1.0 - a - b};
}

TEST(MergeVisibility, OneProductEqualsTheBarycentricSumOfThree) {
  std::mt19937 rng(8);
  SparseHaar merged;
  PreparedVisibility prepared;
  for (int level = 1; level <= 6; ++level) {
    for (int trial = 0; trial < 4; ++trial) {
      const std::array<SparseHaar, 3> v = vertexVisibility(level, rng);
      const std::array<double, 3> w = randomBarycentrics(rng);
      const SparseHaar light = keepLargest(forwardHaar(randomMap(level, 0.0, 3.0, rng).weightedBySolidAngle()), 256);
      const HaarMap brdf = forwardHaar(randomMap(level, 0.0, 2.0, rng));
      mergeVisibility({&v[0], &v[1], &v[2]}, w, merged);

      double expected = 0.0, scale = 0.0;
      for (std::size_t k = 0; k < 3; ++k) {
        expected += w[k] * tripleProduct(light, brdf, v[k]);
        scale += w[k] * magnitude(light, brdf, v[k]);
      }
      prepared.assign(merged);
      EXPECT_NEAR(tripleProduct(PreparedLight(light), brdf, prepared), expected, 1e-6 * scale)
          << "level " << level << " trial " << trial;

      // The list itself: strictly increasing indices, the weighted sum of the three.
      for (std::size_t k = 1; k < merged.size(); ++k) ASSERT_LT(merged.index[k - 1], merged.index[k]);
      const HaarMap dense = merged.toDense();
      const std::array<HaarMap, 3> dv{v[0].toDense(), v[1].toDense(), v[2].toDense()};
      for (std::size_t i = 0; i < dense.coefficientCount(); ++i) {
        const double sum = w[0] * dv[0][i] + w[1] * dv[1][i] + w[2] * dv[2][i];
        ASSERT_NEAR(dense[i], sum, 1e-6 * (std::abs(sum) + 1e-3)) << "coefficient " << i;
      }
    }
  }
}

TEST(MergeVisibility, ZeroWeightsAndSharedVertices) {
  std::mt19937 rng(12);
  const std::array<SparseHaar, 3> v = vertexVisibility(4, rng);
  SparseHaar merged;
  mergeVisibility({&v[0], &v[1], &v[2]}, {1.0, 0.0, 0.0}, merged);
  EXPECT_EQ(merged.index, v[0].index);
  EXPECT_EQ(merged.value, v[0].value);
  mergeVisibility({&v[1], &v[1], &v[2]}, {0.25, 0.75, 0.0}, merged);
  EXPECT_EQ(merged.index, v[1].index);
  for (std::size_t k = 0; k < merged.size(); ++k) EXPECT_FLOAT_EQ(merged.value[k], v[1].value[k]);
}

TEST(MergeVisibility, BadListsAreRefused) {
  const SparseHaar a{3, {0, 5}, {1.0f, 0.5f}}, b{4, {0}, {1.0f}}, unsorted{3, {5, 0}, {1.0f, 1.0f}}, ragged{3, {0, 1}, {1.0f}},
                   repeated{3, {0, 5, 5}, {1.0f, 1.0f, 1.0f}};
  SparseHaar out;
  EXPECT_THROW(mergeVisibility({&a, &a, &b}, {0.3, 0.3, 0.4}, out), std::invalid_argument);
  EXPECT_THROW(mergeVisibility({&a, nullptr, &a}, {0.3, 0.3, 0.4}, out), std::invalid_argument);
  EXPECT_THROW(mergeVisibility({&a, &unsorted, &a}, {0.3, 0.3, 0.4}, out), std::invalid_argument);
  EXPECT_THROW(mergeVisibility({&a, &ragged, &a}, {0.3, 0.3, 0.4}, out), std::invalid_argument);
  EXPECT_THROW(mergeVisibility({&a, &a, &repeated}, {0.3, 0.3, 0.4}, out), std::invalid_argument);
}

// The counter the warm-call tests rely on sees an allocation at all.
TEST(MergeVisibility, AllocationCounterSeesAnAllocation) {
  const testing::AllocationCounter counter;
  std::vector<double> v(100);
  EXPECT_GE(counter.count(), 1u);
  EXPECT_EQ(v.size(), 100u);
}

TEST(MergeVisibility, WarmPixelAllocatesNothing) {
  std::mt19937 rng(13);
  const int level = 5;
  std::array<PreparedLight, 3> light;
  std::array<HaarMap, 3> brdf;
  for (std::size_t c = 0; c < 3; ++c) {
    light[c].assign(keepLargest(forwardHaar(randomMap(level, 0.0, 3.0, rng).weightedBySolidAngle()), 256));
    brdf[c] = forwardHaar(randomMap(level, 0.0, 1.0, rng));
  }
  std::vector<std::array<SparseHaar, 3>> triangles;
  for (int t = 0; t < 8; ++t) triangles.push_back(vertexVisibility(level, rng));
  SparseHaar merged;
  PreparedVisibility prepared;
  TripleProductScratch scratch;
  double radiance = 0.0;
  auto shadePixel = [&](const std::array<SparseHaar, 3>& v) {
    mergeVisibility({&v[0], &v[1], &v[2]}, {0.2, 0.3, 0.5}, merged);
    prepared.assign(merged);
    for (std::size_t c = 0; c < 3; ++c) radiance += tripleProduct(light[c], brdf[c], prepared);
    radiance += tripleProduct(light[0], brdf[0], merged, scratch);
  };
  // Warm: buffers grow to the largest pixel's lists.
  for (const auto& v : triangles) shadePixel(v);
  const testing::AllocationCounter counter;
  for (const auto& v : triangles) shadePixel(v);
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_TRUE(std::isfinite(radiance));
}

}  // namespace
}  // namespace haarcast
