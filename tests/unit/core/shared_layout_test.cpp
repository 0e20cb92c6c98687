// The Haar numbers of core/shared_layout.h (one definition for C++ and GLSL)
// against what they stand for: the quadrant layout of HaarMap, the signs of
// inverseHaar's synthesis, and the pre-order walk of the block quadtree;
// and `fused`'s row range (passRows) against the directions it leaves out.
// (tests/unit/gpu/shared_layout_test.cpp checks the GLSL reading against these.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <vector>

#include "haarcast/core/haar.h"
#include "haarcast/core/shared_layout.h"
#include "haarcast/core/sphere_map.h"

namespace haarcast {
namespace {

using shared::uint;

// Every index of levels 1–7 is a detail position that maps back to itself,
// and coefficientPosition reads it alike.
TEST(SharedLayout, DetailPositionInvertsDetailIndex) {
  for (uint n = 1; n <= 7; ++n) {
    const uint m = 1u << n;
    for (uint index = 1; index < m * m; ++index) {
      const shared::HaarDetailPosition p = shared::haarDetailPosition(n, index);
      ASSERT_LT(p.level, n);
      ASSERT_LT(p.band, 3u);
      ASSERT_LT(p.i, 1u << p.level);
      ASSERT_LT(p.j, 1u << p.level);
      ASSERT_EQ(shared::haarDetailIndex(m, p.band, p.level, p.i, p.j), index) << "level " << n;
      const CoefficientPosition c = coefficientPosition(static_cast<int>(n), index);
      ASSERT_FALSE(c.isScaling);
      ASSERT_EQ(static_cast<uint>(c.band), p.band);
      ASSERT_EQ(static_cast<uint>(c.level), p.level);
      ASSERT_EQ(static_cast<uint>(c.i), p.i);
      ASSERT_EQ(static_cast<uint>(c.j), p.j);
    }
  }
  // The documented places: h top-right, v bottom-left, d bottom-right of the
  // level's 2^(l+1) square.
  EXPECT_EQ(shared::haarDetailIndex(8, 0, 1, 1, 0), 1u * 8 + 2);
  EXPECT_EQ(shared::haarDetailIndex(8, 1, 1, 1, 0), 3u * 8 + 0);
  EXPECT_EQ(shared::haarDetailIndex(8, 2, 1, 1, 0), 3u * 8 + 2);
}

// The child signs are those of inverseHaar: a level-1 map whose only
// coefficient is one detail synthesises ±1/2 in each quadrant.
TEST(SharedLayout, ChildSignsAreTheSynthesisSigns) {
  for (uint band = 0; band < 3; ++band) {
    HaarMap map(1);
    map[shared::haarDetailIndex(2, band, 0, 0, 0)] = 1.0f;
    const SphereMap pixels = inverseHaar(map);
    for (uint row = 0; row < 2; ++row) {
      for (uint col = 0; col < 2; ++col) {
        const shared::vec3 sign = shared::haarChildSign(shared::haarChildQuadrant(row, col));
        EXPECT_EQ(sign[static_cast<int>(band)], 2.0f * pixels.at(static_cast<int>(row), static_cast<int>(col)))
            << "band " << band << ", quadrant (" << row << ", " << col << ")";
      }
    }
  }
  EXPECT_EQ(shared::haarChildQuadrant(4, 7), 1u);  // even row, odd column: top-right
  EXPECT_EQ(shared::haarChildQuadrant(5, 2), 2u);
}

// Keys increase along the pre-order walk (a block, then its four children in
// quadrant order), and decode back to their block.
void walk(uint finest, uint l, uint i, uint j, std::vector<std::uint64_t>& keys) {
  const uint key = shared::haarPreorderKey(finest, l, i, j);
  keys.push_back(key);
  const shared::HaarBlock b = shared::haarPreorderBlock(finest, key);
  ASSERT_EQ(b.level, l);
  ASSERT_EQ(b.i, i);
  ASSERT_EQ(b.j, j);
  if (l == finest) return;
  for (uint q = 0; q < 4; ++q) walk(finest, l + 1, 2 * i + (q >> 1), 2 * j + (q & 1), keys);
}

TEST(SharedLayout, PreorderKeysFollowTheQuadtreeWalk) {
  for (uint n = 1; n <= 7; ++n) {
    std::vector<std::uint64_t> keys;
    walk(n - 1, 0, 0, 0, keys);
    for (std::size_t k = 1; k < keys.size(); ++k) ASSERT_LT(keys[k - 1], keys[k]) << "level " << n << ", step " << k;
  }
  // The finest block of the largest map whose keys fit 32 bits, corner to corner.
  const uint finest = shared::kMaxPreorderLevel - 1, last = (1u << finest) - 1;
  const shared::HaarBlock b = shared::haarPreorderBlock(finest, shared::haarPreorderKey(finest, finest, last, last));
  EXPECT_EQ(b.i, last);
  EXPECT_EQ(b.j, last);
  EXPECT_EQ(b.level, finest);
  static_assert(shared::haarPreorderKey(3, 0, 0, 0) == 0u && shared::haarPreorderKey(3, 3, 0, 1) == ((1u << 4) | 3u));
}

}  // namespace
}  // namespace haarcast

namespace haarcast {
namespace {

// passRows may leave out only rows every direction of which is below the
// slices' cut (y₂ = cos θ' < skipBelowY, so it reads zero texels): the
// pass's sums are then those of the whole map. For rotations and cuts all
// over, every direction of a left-out row is checked; and the range is
// much less than the map where the cut is high.
TEST(SharedLayout, PassRowsLeaveOutOnlyRowsBelowTheCut) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::size_t leftOut = 0, checked = 0;
  for (int level : {2, 4, 6}) {
    const int m = mapSize(level);
    for (int trial = 0; trial < 200; ++trial) {
      const float alpha = 6.2831853f * u(rng), beta = 3.1415927f * u(rng);
      const float skipBelowY = trial % 10 == 0 ? -2.0f : 2.0f * u(rng) - 1.0f;
      const shared::uvec2 rows = shared::passRows(static_cast<shared::uint>(m), std::cos(beta), skipBelowY);
      ASSERT_LE(rows.x, rows.y);
      ASSERT_LE(rows.y, static_cast<shared::uint>(m));
      if (!(skipBelowY > -1.0f)) {
        EXPECT_EQ(rows.x, 0u);
        EXPECT_EQ(rows.y, static_cast<shared::uint>(m));
      }
      for (int r = 0; r < m; ++r) {
        if (r >= static_cast<int>(rows.x) && r < static_cast<int>(rows.y)) continue;
        ++leftOut;
        for (int c = 0; c < m; ++c) {
          const glm::dvec3 w = sphericalToDirection(rowTheta(level, r), colPhi(level, c));
          // y₂ of R_x(−β)R_y(−α)ω, as fused_kernel.cpp forms it.
          const double z1 = std::sin(alpha) * w.x + std::cos(alpha) * w.z;
          const double y2 = std::cos(beta) * w.y + std::sin(beta) * z1;
          ++checked;
          ASSERT_LT(y2, skipBelowY) << "level " << level << " row " << r << " column " << c << ", rows " << rows.x << "…"
                                    << rows.y;
        }
      }
    }
  }
  std::printf("%zu rows left out, %zu directions checked\n", leftOut, checked);
  EXPECT_GT(leftOut, 1000u) << "the test must see rows left out";
}

}  // namespace
}  // namespace haarcast
