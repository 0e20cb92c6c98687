// `fused`'s adaptive sum (shared_cells.h, fused_cells.h): the cell layout
// against the row-major bits and the map's directions, and the sum by cells
// against the sum over every direction.
#include <gtest/gtest.h>
#include <hwy/targets.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <vector>

#include "haarcast/core/brdf.h"
#include "haarcast/core/fused.h"
#include "haarcast/core/fused_cells.h"
#include "haarcast/core/rotation.h"
#include "haarcast/core/shared_cells.h"
#include "haarcast/core/visibility_bits.h"

namespace haarcast {
namespace {

TEST(SharedCells, CellBitsAreTheRowMajorBitsOfTheCellsDirections) {
  std::mt19937 rng(5);
  for (shared::uint level : {5u, 6u, 7u}) {
    const shared::uint m = 1u << level;
    std::vector<shared::uint> words(m * m / 32u);
    for (auto& w : words) w = static_cast<shared::uint>(rng());
    for (shared::uint q = 0; q < shared::cellsAcross(m) * shared::cellsAcross(m); ++q) {
      const shared::uint bits =
          shared::cellBits(words[shared::cellWordIndex(m, q, 0)], words[shared::cellWordIndex(m, q, 1)],
                           words[shared::cellWordIndex(m, q, 2)], words[shared::cellWordIndex(m, q, 3)], shared::cellShift(m, q));
      for (shared::uint k = 0; k < shared::kCellDirections; ++k) {
        const shared::uint i = shared::cellDirection(m, q, k);
        ASSERT_EQ((bits >> k) & 1u, (words[i / 32u] >> (i % 32u)) & 1u) << "level " << level << " cell " << q << " k " << k;
      }
    }
  }
}

// A point's cell masks say which cells its bits see whole and which any
// of, against the cell's 16 bits; the word past each set stays zero (the
// pass reads the 32 cells from any cell as two words).
TEST(SharedCells, CellMasksAreWhichCellsAPointSeesWholeAndWhichAny) {
  std::mt19937 rng(11);
  for (int level : {5, 6, 7}) {
    const shared::uint m = 1u << level;
    const std::size_t cells = shared::cellsAcross(m) * shared::cellsAcross(m);
    VisibilityBits bits(level, 2);
    for (std::size_t p = 0; p < 2; ++p) {
      // Whole, empty and mixed cells alike: most are one of the first two.
      const std::span<std::uint32_t> w = bits.point(p);
      for (shared::uint q = 0; q < cells; ++q) {
        const std::uint32_t r = static_cast<std::uint32_t>(rng());
        const std::uint32_t pattern = (r & 3u) == 0u ? static_cast<std::uint32_t>(rng()) : ((r & 4u) ? 0xFFFFu : 0u);
        for (shared::uint k = 0; k < shared::kCellDirections; ++k) {
          const shared::uint i = shared::cellDirection(m, q, k);
          if ((pattern >> k) & 1u) w[i / 32] |= 1u << (i % 32);
        }
      }
    }
    const CellVisibility masks = CellVisibility::fromBits(bits);
    const std::size_t words = cellMaskWords(level);
    ASSERT_EQ(words, cells / 32 + 1);
    std::size_t whole = 0, none = 0;
    for (std::size_t p = 0; p < 2; ++p) {
      const std::span<const std::uint32_t> w = bits.point(p);
      const std::uint32_t* set = masks.point(p);
      for (shared::uint q = 0; q < cells; ++q) {
        const shared::uint b = shared::cellBits(w[shared::cellWordIndex(m, q, 0)], w[shared::cellWordIndex(m, q, 1)],
                                                w[shared::cellWordIndex(m, q, 2)], w[shared::cellWordIndex(m, q, 3)], shared::cellShift(m, q));
        ASSERT_EQ((set[q / 32] >> (q % 32)) & 1u, b == shared::kCellAll ? 1u : 0u) << "level " << level << " cell " << q;
        ASSERT_EQ((set[words + q / 32] >> (q % 32)) & 1u, b != 0u ? 1u : 0u) << "level " << level << " cell " << q;
        whole += b == shared::kCellAll;
        none += b == 0u;
      }
      EXPECT_EQ(set[words - 1], 0u);
      EXPECT_EQ(set[2 * words - 1], 0u);
    }
    EXPECT_GT(whole, cells / 4);
    EXPECT_GT(none, cells / 4);
    EXPECT_LT(whole + none, 2 * cells);
  }
}

// The cells tile the sphere, and cellReach bounds (tightly) how far a
// cell's directions lie from its centre: the lobe path's core test and the
// error bound rest on it.
TEST(SharedCells, EveryDirectionOfACellIsWithinItsReach) {
  for (int level : {5, 6, 7}) {
    const CellDirections& c = cellDirections(level);
    double farthest = 0.0, omega = 0.0;
    for (std::size_t q = 0; q < c.x.size() / shared::kCellDirections; ++q) {
      const glm::dvec3 centre(c.centreX[q], c.centreY[q], c.centreZ[q]);
      omega += c.cellSolidAngle[q];
      for (std::size_t k = 0; k < shared::kCellDirections; ++k) {
        const std::size_t i = q * shared::kCellDirections + k;
        farthest = std::max(farthest, std::acos(std::min(1.0, glm::dot(centre, glm::dvec3(c.x[i], c.y[i], c.z[i])))));
      }
    }
    const double reach = shared::cellReach(1u << level);
    EXPECT_LE(farthest, reach) << "level " << level;
    EXPECT_GT(farthest, 0.9 * reach) << "level " << level;
    EXPECT_NEAR(omega, 4.0 * kPi, 1e-3);
  }
}

TEST(SharedCells, VisibilityIsOneNumberOnlyWhereEachWeightedVertexSeesAllOrNone) {
  EXPECT_FLOAT_EQ(shared::cellVisibility(shared::kCellAll, 0u, shared::kCellAll, 0.2f, 0.3f, 0.5f), 0.7f);
  EXPECT_FLOAT_EQ(shared::cellVisibility(0u, 0u, 0u, 0.2f, 0.3f, 0.5f), 0.0f);
  // A vertex of weight 0 (the pixel on the triangle's far edge) does not count.
  EXPECT_FLOAT_EQ(shared::cellVisibility(shared::kCellAll, 0x00F0u, 0u, 0.4f, 0.0f, 0.6f), 0.4f);
  EXPECT_LT(shared::cellVisibility(shared::kCellAll, 0x00F0u, 0u, 0.4f, 0.1f, 0.5f), 0.0f);
}

// A surface's view of a scene: a light with a gradient and a small bright
// blob the light split did not take (so a cell's light varies inside it),
// three vertices whose visibility is a tilted horizon less a neighbour's
// disc (so cells along two edges are mixed), and a pixel turned toward them.
struct Pixel {
  int level = 6;
  FusedLight light;
  VisibilityBits bits;
  EulerYXY r{0.4, 0.7, -1.2};
  std::array<float, 3> b = {0.3f, 0.45f, 0.25f};
};

Pixel makePixel(int level, float tolerance) {
  Pixel p;
  p.level = level;
  const glm::dvec3 blob = glm::normalize(glm::dvec3(0.5, 0.8, 0.3));
  std::array<SphereMap, 3> light;
  for (std::size_t c = 0; c < 3; ++c) {
    SphereMap map(level);
    for (int i = 0; i < map.size(); ++i) {
      for (int j = 0; j < map.size(); ++j) {
        const glm::dvec3 w = sphericalToDirection(rowTheta(level, i), colPhi(level, j));
        const double a = std::acos(std::clamp(glm::dot(w, blob), -1.0, 1.0));
        map.at(i, j) = static_cast<float>((0.2 + 0.1 * c) + 0.3 * std::max(w.y, 0.0) + 20.0 * std::exp(-a * a / (2.0 * 0.08 * 0.08)));
      }
    }
    light[c] = map.weightedBySolidAngle();
  }
  p.light = FusedLight::fromWeightedMaps(light, tolerance);
  const glm::dvec3 normal = glm::dmat3(rotationMatrix(p.r)) * glm::dvec3(0.0, 1.0, 0.0);
  const glm::dvec3 neighbour = glm::normalize(normal + glm::dvec3(-0.7, 0.0, 0.3));
  p.bits = VisibilityBits(level, 3);
  for (std::size_t v = 0; v < 3; ++v) {
    const glm::dvec3 n = glm::normalize(normal + 0.05 * static_cast<double>(v) * glm::dvec3(1.0, 0.0, 1.0));
    for (std::size_t i = 0; i < p.bits.directions(); ++i) {
      const int m = mapSize(level);
      const glm::dvec3 w = sphericalToDirection(rowTheta(level, static_cast<int>(i) / m), colPhi(level, static_cast<int>(i) % m));
      const bool open = glm::dot(w, n) > -0.05 && glm::dot(w, neighbour) < std::cos(0.4 + 0.03 * static_cast<double>(v));
      if (open) p.bits.point(v)[i / 32] |= 1u << (i % 32);
    }
  }
  return p;
}

struct Shaded {
  std::array<float, 3> rgb;
  std::size_t directions;
  CellCounts counts;
};
Shaded shade(const PixelSlices& slices, const Pixel& p, const shared::SliceBlend& blend) {
  const std::array<WeightedBits, 3> v = {WeightedBits{p.bits.point(0).data(), p.b[0]}, WeightedBits{p.bits.point(1).data(), p.b[1]},
                                         WeightedBits{p.bits.point(2).data(), p.b[2]}};
  FusedScratch scratch;
  const std::array<float, 3> rgb = fusedShade(slices, blend, p.r, p.light, v, {}, 0u, scratch);
  return {rgb, scratch.passDirections, scratch.cellCounts};
}

double relativeError(const std::array<float, 3>& a, const std::array<float, 3>& want) {
  double e = 0.0, w = 0.0;
  for (std::size_t c = 0; c < 3; ++c) {
    e += (a[c] - want[c]) * (a[c] - want[c]);
    w += want[c] * want[c];
  }
  return std::sqrt(e / w);
}

PixelSlices slicesOf(const Brdf& brdf, int level) {
  SliceTableOptions options;
  options.level = level;
  options.thetaSamples = 4;
  return PixelSlices::synthesize(BrdfSliceTable::build(brdf, options), nullptr, true);
}

// With a tolerance below every detail, every cell that can add anything
// is summed direction by direction: the full sum, in another order.
TEST(FusedCells, BelowEveryDetailTheSumIsTheFullSum) {
  const auto brdf = makeGgx({0.1, 0.1, 0.1}, {0.9, 0.8, 0.6}, 0.3);
  const PixelSlices slices = slicesOf(*brdf, 5);
  const Pixel full = makePixel(5, 0.0f), cells = makePixel(5, 1e-7f);
  for (const shared::SliceBlend blend : {shared::SliceBlend{1u, 1u, 0.0f}, shared::SliceBlend{1u, 2u, 0.4f}}) {
    const Shaded want = shade(slices, full, blend), got = shade(slices, cells, blend);
    EXPECT_LT(relativeError(got.rgb, want.rgb), 2e-6);
    EXPECT_GT(got.counts.fine, 0u);
  }
}

// A Lambert slice is smooth: at the default tolerance every cell is summed
// at one direction (mixed ones by their V·L), within 0.3 % of the full sum
// (0.21 % here) and at under a fifth of its directions.
TEST(FusedCells, ALambertSliceIsSummedCoarseWithinAFractionOfAPercent) {
  const auto brdf = makeLambert({0.7, 0.6, 0.5});
  const PixelSlices slices = slicesOf(*brdf, 6);
  const Pixel full = makePixel(6, 0.0f), cells = makePixel(6, shared::kDefaultSumTolerance);
  const shared::SliceBlend blend{2u, 3u, 0.25f};
  const Shaded want = shade(slices, full, blend), got = shade(slices, cells, blend);
  EXPECT_LT(relativeError(got.rgb, want.rgb), 3e-3);
  EXPECT_EQ(got.counts.fine, 0u);
  EXPECT_GT(got.counts.mixed, 0u);  // the horizon's and the neighbour's edges
  EXPECT_LT(got.directions * 5, want.directions);
}

// A sharp lobe is summed fine where its slice has detail and coarse
// elsewhere: within 0.5 % of the full sum.
TEST(FusedCells, ASharpLobeIsSummedFineWhereItIs) {
  const auto brdf = makeGgx({0.05, 0.05, 0.05}, {0.9, 0.8, 0.6}, 0.1);
  const PixelSlices slices = slicesOf(*brdf, 6);
  const Pixel full = makePixel(6, 0.0f), cells = makePixel(6, shared::kDefaultSumTolerance);
  for (const shared::SliceBlend blend : {shared::SliceBlend{0u, 0u, 0.0f}, shared::SliceBlend{2u, 3u, 0.5f}}) {
    const Shaded want = shade(slices, full, blend), got = shade(slices, cells, blend);
    EXPECT_LT(relativeError(got.rgb, want.rgb), 5e-3);
    EXPECT_GT(got.counts.fine, 0u);
    EXPECT_LT(got.directions * 3, want.directions * 2);
  }
}

// Both kernels on every SIMD target this machine has (Highway's dispatch,
// mocked target by target): the vectors are 4, 8 or 16 lanes, a cell's 16
// directions one to four of them, and the sums agree to float rounding.
TEST(FusedCells, EveryTargetSumsAlike) {
  const auto lambert = makeLambert({0.7, 0.6, 0.5});
  const auto sharp = makeGgx({0.05, 0.05, 0.05}, {0.9, 0.8, 0.6}, 0.1);
  const PixelSlices slices[2] = {slicesOf(*lambert, 6), slicesOf(*sharp, 6)};
  const Pixel pixels[2] = {makePixel(6, 0.0f), makePixel(6, shared::kDefaultSumTolerance)};
  const shared::SliceBlend blend{2u, 3u, 0.25f};
  const std::vector<std::int64_t> targets = hwy::SupportedAndGeneratedTargets();
  ASSERT_FALSE(targets.empty());
  std::vector<Shaded> first;
  for (const std::int64_t target : targets) {
    hwy::SetSupportedTargetsForTest(target);
    std::size_t k = 0;
    for (const PixelSlices& s : slices) {
      for (const Pixel& p : pixels) {
        const Shaded got = shade(s, p, blend);
        if (first.size() <= k) {
          first.push_back(got);
        } else {
          EXPECT_LT(relativeError(got.rgb, first[k].rgb), 1e-5) << hwy::TargetName(target) << ", case " << k;
          EXPECT_EQ(got.directions, first[k].directions) << hwy::TargetName(target) << ", case " << k;
        }
        ++k;
      }
    }
  }
  hwy::SetSupportedTargetsForTest(0);
  std::printf("targets compared: %zu\n", targets.size());
}

TEST(FusedCells, ANegativeToleranceIsRefused) {
  std::array<SphereMap, 3> light{SphereMap(5), SphereMap(5), SphereMap(5)};
  EXPECT_THROW(FusedLight::fromWeightedMaps(light, -0.1f), std::invalid_argument);
  // Below level 5 the light keeps no cells: every direction is summed.
  std::array<SphereMap, 3> small{SphereMap(4), SphereMap(4), SphereMap(4)};
  EXPECT_FALSE(FusedLight::fromWeightedMaps(small, 0.5f).sumsByCells());
  EXPECT_TRUE(FusedLight::fromWeightedMaps(light, 0.5f).sumsByCells());
}

}  // namespace
}  // namespace haarcast
