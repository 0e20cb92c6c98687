#include "haarcast/core/haar.h"

#include <algorithm>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

namespace haarcast {
namespace {

SphereMap randomMap(int level, unsigned seed) {
  SphereMap m(level);
  std::mt19937 rng(seed);
  std::normal_distribution<float> n(0.0f, 1.0f);
  for (float& v : m.values()) v = n(rng);
  return m;
}

TEST(Haar, DesignBlockFormulasAtLevelOne) {
  SphereMap m(1);
  m.at(0, 0) = 1.0f;  // a
  m.at(0, 1) = 2.0f;  // b
  m.at(1, 0) = 5.0f;  // c
  m.at(1, 1) = 11.0f; // d
  const HaarMap c = forwardHaar(m);
  EXPECT_FLOAT_EQ(c.scaling(), (1 + 2 + 5 + 11) / 2.0f);
  EXPECT_FLOAT_EQ(c.detail(Band::Horizontal, 0, 0, 0), (1 - 2 + 5 - 11) / 2.0f);
  EXPECT_FLOAT_EQ(c.detail(Band::Vertical, 0, 0, 0), (1 + 2 - 5 - 11) / 2.0f);
  EXPECT_FLOAT_EQ(c.detail(Band::Diagonal, 0, 0, 0), (1 - 2 - 5 + 11) / 2.0f);
  // Quadrant layout: h top-right, v bottom-left, d bottom-right.
  EXPECT_EQ(c.detailIndex(Band::Horizontal, 0, 0, 0), 1u);
  EXPECT_EQ(c.detailIndex(Band::Vertical, 0, 0, 0), 2u);
  EXPECT_EQ(c.detailIndex(Band::Diagonal, 0, 0, 0), 3u);
}

TEST(Haar, PerfectReconstruction) {
  for (int level = 0; level <= 7; ++level) {
    const SphereMap m = randomMap(level, 10u + static_cast<unsigned>(level));
    const SphereMap back = inverseHaar(forwardHaar(m));
    for (std::size_t i = 0; i < m.pixelCount(); ++i)
      ASSERT_NEAR(back.values()[i], m.values()[i], 2e-5) << "level " << level << " pixel " << i;
  }
}

TEST(Haar, Parseval) {
  for (int level = 1; level <= 7; ++level) {
    const SphereMap m = randomMap(level, 20u + static_cast<unsigned>(level));
    const HaarMap c = forwardHaar(m);
    double pixels = 0.0, coeffs = 0.0;
    for (float v : m.values()) pixels += static_cast<double>(v) * v;
    for (float v : c.coefficients()) coeffs += static_cast<double>(v) * v;
    EXPECT_NEAR(coeffs / pixels, 1.0, 1e-6) << "level " << level;
  }
}

TEST(Haar, BasisIsOrthonormal) {
  const int level = 3;
  const std::size_t n = 64;
  std::vector<SphereMap> basis;
  for (std::size_t i = 0; i < n; ++i) {
    HaarMap e(level);
    e[i] = 1.0f;
    basis.push_back(inverseHaar(e));
  }
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      double dot = 0.0;
      for (std::size_t p = 0; p < n; ++p) dot += static_cast<double>(basis[i].values()[p]) * basis[j].values()[p];
      ASSERT_NEAR(dot, i == j ? 1.0 : 0.0, 1e-6) << i << "," << j;
    }
}

TEST(Haar, CoefficientPositionInvertsDetailIndex) {
  const int level = 4;
  HaarMap c(level);
  EXPECT_TRUE(coefficientPosition(level, 0).isScaling);
  std::vector<int> seen(c.coefficientCount(), 0);
  for (int l = 0; l < level; ++l)
    for (int b = 0; b < 3; ++b)
      for (int i = 0; i < (1 << l); ++i)
        for (int j = 0; j < (1 << l); ++j) {
          const std::size_t idx = c.detailIndex(static_cast<Band>(b), l, i, j);
          ++seen[idx];
          const CoefficientPosition p = coefficientPosition(level, idx);
          EXPECT_FALSE(p.isScaling);
          EXPECT_EQ(static_cast<int>(p.band), b);
          EXPECT_EQ(p.level, l);
          EXPECT_EQ(p.i, i);
          EXPECT_EQ(p.j, j);
          EXPECT_EQ(supportSide(level, idx), 1 << (level - l));
        }
  // Every index but the scaling one is exactly one detail.
  EXPECT_EQ(std::count(seen.begin() + 1, seen.end(), 1), static_cast<long>(c.coefficientCount() - 1));
}

TEST(Haar, ScalingValuesAreBlockSumsOverSide) {
  const int level = 5;
  const SphereMap m = randomMap(level, 7);
  const HaarMap c = forwardHaar(m);
  for (int l = 0; l <= level; ++l) {
    const std::vector<double> s = scalingValues(c, l);
    const int side = 1 << (level - l);
    for (int i = 0; i < (1 << l); ++i)
      for (int j = 0; j < (1 << l); ++j) {
        double sum = 0.0;
        for (int r = 0; r < side; ++r)
          for (int q = 0; q < side; ++q) sum += m.at(i * side + r, j * side + q);
        EXPECT_NEAR(s[static_cast<std::size_t>(i) * (1u << l) + j], sum / side, 1e-4) << l << " " << i << " " << j;
      }
  }
}

TEST(Haar, KeepLargestTakesTheLargestAreaWeightedMagnitudes) {
  const int level = 5;
  const HaarMap c = forwardHaar(randomMap(level, 9));
  for (std::size_t k : {1u, 10u, 100u, 1000u}) {
    const SparseHaar s = keepLargest(c, k);
    ASSERT_EQ(s.size(), k);
    EXPECT_TRUE(std::is_sorted(s.index.begin(), s.index.end()));
    // Brute force: the k-th largest weight bounds every kept one from below
    // and every dropped one from above.
    std::vector<double> w(c.coefficientCount());
    for (std::size_t i = 0; i < w.size(); ++i) w[i] = std::abs(c[i]) * supportSide(level, i);
    std::vector<double> sorted = w;
    std::sort(sorted.begin(), sorted.end(), std::greater<>());
    const double kth = sorted[k - 1];
    std::vector<bool> kept(w.size(), false);
    for (std::size_t n = 0; n < s.size(); ++n) {
      kept[s.index[n]] = true;
      EXPECT_EQ(s.value[n], c[s.index[n]]);
      EXPECT_GE(w[s.index[n]], kth);
    }
    for (std::size_t i = 0; i < w.size(); ++i) {
      if (!kept[i]) {
        EXPECT_LE(w[i], kth);
      }
    }
  }
  EXPECT_EQ(keepLargest(c, 1u << 20).size(), SparseHaar::fromDense(c).size());
}

TEST(Haar, SparseRoundTrip) {
  HaarMap c(3);
  c[0] = 1.5f;
  c[17] = -2.0f;
  c[63] = 0.25f;
  const SparseHaar s = SparseHaar::fromDense(c);
  ASSERT_EQ(s.size(), 3u);
  const HaarMap back = s.toDense();
  for (std::size_t i = 0; i < c.coefficientCount(); ++i) EXPECT_EQ(back[i], c[i]);
}

}  // namespace
}  // namespace haarcast
