// `fused` against what it replaces: `spatial` rotation + the Haar triple
// product, on random maps, rotations and sparse light and visibility.
#include "haarcast/core/fused.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "haarcast/core/brdf.h"
#include "haarcast/core/triple_product.h"
#include "test_maps.h"

namespace haarcast {
namespace {

using testing::randomSparse;

std::vector<double> thetaOutLayout(int t) {
  std::vector<double> out;
  for (int k = 0; k < t; ++k) out.push_back((k + 0.5) * (kPi / 2.0) / t);
  return out;
}

// A table of random slices: every texel non-zero, or (upperOnly) zero below
// the equator like a real ρ·cos θᵢ slice, which engages the pass's skip.
BrdfSliceTable randomTable(int level, int thetaSamples, bool upperOnly, std::mt19937& rng) {
  std::uniform_real_distribution<double> dist(0.05, 1.0);
  std::vector<HaarMap> slices;
  for (int c = 0; c < 3; ++c) {
    for (int t = 0; t < thetaSamples; ++t) {
      SphereMap map(level);
      for (int i = 0; i < map.size(); ++i)
        for (int j = 0; j < map.size(); ++j)
          map.at(i, j) = (upperOnly && i >= map.size() / 2) ? 0.0f : static_cast<float>(dist(rng));
      slices.push_back(forwardHaar(map));
    }
  }
  return BrdfSliceTable::fromSlices(thetaOutLayout(thetaSamples), std::move(slices));
}

struct Case {
  BrdfSliceTable table;
  std::array<SparseHaar, 3> light;
  std::array<SparseHaar, 3> visibility;
  std::array<float, 3> weights{};
};

Case randomCase(int level, bool upperOnly, std::mt19937& rng) {
  Case c;
  c.table = randomTable(level, 3, upperOnly, rng);
  for (auto& l : c.light) l = randomSparse(level, 64, -0.3, 0.3, rng);
  for (auto& v : c.visibility) v = randomSparse(level, 48, -0.5, 0.5, rng);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const float a = u(rng), b = u(rng) * (1.0f - a);
  c.weights = {a, b, 1.0f - a - b};
  return c;
}

std::array<WeightedVisibility, 3> weighted(const Case& c) {
  return {WeightedVisibility{&c.visibility[0], c.weights[0]}, WeightedVisibility{&c.visibility[1], c.weights[1]},
          WeightedVisibility{&c.visibility[2], c.weights[2]}};
}

// What `spatial` + the triple product give for channel c of slice t, times
// `fused`'s energy factor ∫ρ / Σ ΔΩ·ρ(Rᵀω) (the slice's integral over the
// rotated map's: fused.h), and Σ|L|·|V|·|ρ| over pixels to scale the
// tolerance by.
struct Reference {
  double value = 0.0;
  double magnitude = 0.0;
};
Reference reference(const Case& c, int channel, int t, const EulerYXY& r) {
  const HaarMap rotated = rotateSpatial(c.table.slice(channel, t), r);
  Reference out;
  const SphereMap light = inverseHaar(c.light[static_cast<std::size_t>(channel)].toDense());
  const SphereMap rho = inverseHaar(rotated);
  for (std::size_t v = 0; v < 3; ++v) {
    out.value += c.weights[v] * tripleProduct(c.light[static_cast<std::size_t>(channel)], rotated, c.visibility[v]);
    const SphereMap vis = inverseHaar(c.visibility[v].toDense());
    for (std::size_t p = 0; p < rho.pixelCount(); ++p) {
      out.magnitude += c.weights[v] * std::abs(light.values()[p] * vis.values()[p] * rho.values()[p]);
    }
  }
  const double factor = inverseHaar(c.table.slice(channel, t)).integral() / rho.integral();
  out.value *= factor;
  out.magnitude *= std::abs(factor);
  return out;
}

class FusedLevels : public ::testing::TestWithParam<int> {};

TEST_P(FusedLevels, EqualsSpatialRotationAndTripleProduct) {
  const int level = GetParam();
  std::mt19937 rng(1234u + static_cast<unsigned>(level));
  for (bool upperOnly : {false, true}) {
    const Case c = randomCase(level, upperOnly, rng);
    const PixelSlices slices = PixelSlices::synthesize(c.table);
    const FusedLight light = FusedLight::synthesize(c.light);
    const auto vis = weighted(c);
    FusedScratch scratch;
    int rotation = 0;
    for (const EulerYXY& r : randomRotations(level >= 6 ? 4 : 12, 99u)) {
      const int t = rotation++ % 3;
      const std::array<float, 3> got =
          fusedShade(slices, shared::SliceBlend{static_cast<shared::uint>(t), static_cast<shared::uint>(t), 0.0f}, r,
                     light, vis, scratch);
      for (int ch = 0; ch < 3; ++ch) {
        const Reference want = reference(c, ch, t, r);
        EXPECT_NEAR(got[static_cast<std::size_t>(ch)], want.value, 2e-6 * want.magnitude)
            << "level " << level << (upperOnly ? " upper-hemisphere" : " full") << " slices, channel " << ch
            << ", rotation (" << r.alpha << ", " << r.beta << ", " << r.gamma << ")";
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Fused, FusedLevels, ::testing::Range(2, 8),
                         [](const auto& p) { return "Level" + std::to_string(p.param); });

TEST(Fused, MergedVisibilityIsTheSumOfTheThreeProducts) {
  std::mt19937 rng(7u);
  const Case c = randomCase(5, true, rng);
  const PixelSlices slices = PixelSlices::synthesize(c.table);
  const FusedLight light = FusedLight::synthesize(c.light);
  const EulerYXY r{0.7, 1.1, 2.9};
  const shared::SliceBlend blend{1u, 2u, 0.25f};
  FusedScratch scratch;
  const auto merged = fusedShade(slices, blend, r, light, weighted(c), scratch);
  std::array<double, 3> sum{};
  for (std::size_t v = 0; v < 3; ++v) {
    const WeightedVisibility one{&c.visibility[v], c.weights[v]};
    const auto part = fusedShade(slices, blend, r, light, std::span(&one, 1), scratch);
    for (std::size_t ch = 0; ch < 3; ++ch) sum[ch] += part[ch];
  }
  for (std::size_t ch = 0; ch < 3; ++ch) EXPECT_NEAR(merged[ch], sum[ch], 1e-5 * std::abs(sum[ch]) + 1e-7);
}

TEST(Fused, BlendOfTwoSlicesIsTheBlendedSlicesResult) {
  // Blending two slices' texels in the pass is the same as a table whose
  // slice is their blend (the sums, and the energies, are linear in ρ).
  std::mt19937 rng(8u);
  const Case c = randomCase(4, false, rng);
  const PixelSlices slices = PixelSlices::synthesize(c.table);
  std::vector<HaarMap> mixed;
  for (int ch = 0; ch < 3; ++ch) {
    HaarMap m = c.table.slice(ch, 0);
    const std::span<const float> b = c.table.slice(ch, 1).coefficients();
    std::span<float> a = m.coefficients();
    for (std::size_t k = 0; k < a.size(); ++k) a[k] = 0.7f * a[k] + 0.3f * b[k];
    mixed.push_back(std::move(m));
  }
  const PixelSlices blendedTable = PixelSlices::synthesize(BrdfSliceTable::fromSlices({kPi / 4.0}, std::move(mixed)));
  const FusedLight light = FusedLight::synthesize(c.light);
  const EulerYXY r{2.0, 0.4, 5.0};
  FusedScratch scratch;
  const auto blended = fusedShade(slices, shared::SliceBlend{0u, 1u, 0.3f}, r, light, weighted(c), scratch);
  const auto direct = fusedShade(blendedTable, shared::SliceBlend{0u, 0u, 0.0f}, r, light, weighted(c), scratch);
  for (std::size_t ch = 0; ch < 3; ++ch) EXPECT_NEAR(blended[ch], direct[ch], 1e-5 * std::abs(direct[ch]));
}

TEST(Fused, ScratchSharedAcrossTablesGivesFreshAnswers) {
  // One thread's scratch serves every object: a blend into it for a table
  // whose slices reach the south pole must not leak into the next table's.
  std::mt19937 rng(10u);
  const Case full = randomCase(4, false, rng);
  const Case upper = randomCase(4, true, rng);
  const PixelSlices fullSlices = PixelSlices::synthesize(full.table), upperSlices = PixelSlices::synthesize(upper.table);
  ASSERT_GT(fullSlices.lastNonZeroRow(), upperSlices.lastNonZeroRow());
  const FusedLight light = FusedLight::synthesize(upper.light);
  const EulerYXY r{0.3, 2.6, 1.0};  // a tilt that looks at the lower rows
  const shared::SliceBlend blend{0u, 1u, 0.5f};
  FusedScratch fresh, shared;
  const auto want = fusedShade(upperSlices, blend, r, light, weighted(upper), fresh);
  (void)fusedShade(fullSlices, blend, r, FusedLight::synthesize(full.light), weighted(full), shared);
  const auto got = fusedShade(upperSlices, blend, r, light, weighted(upper), shared);
  for (std::size_t ch = 0; ch < 3; ++ch) EXPECT_EQ(got[ch], want[ch]) << "channel " << ch;
}

TEST(SliceBlend, AtASampleItIsThatSliceAlone) {
  const int samples = 16;
  for (int t = 0; t < samples; ++t) {
    const float theta = static_cast<float>((t + 0.5) * (kPi / 2.0) / samples);
    const shared::SliceBlend b = shared::sliceBlendAt(theta, samples, 1u);
    // The weight is 0 on the lower slice or 1 on the upper one (float rounding
    // may land either side of the centre); either way only slice t counts.
    const double onT = b.first == static_cast<shared::uint>(t) ? 1.0 - b.weight : (b.second == static_cast<shared::uint>(t) ? b.weight : 0.0);
    EXPECT_NEAR(onT, 1.0, 1e-5) << "sample " << t;
    const shared::SliceBlend nearest = shared::sliceBlendAt(theta, samples, 0u);
    EXPECT_EQ(nearest.first, static_cast<shared::uint>(t));
    EXPECT_EQ(nearest.weight, 0.0f);
  }
}

TEST(SliceBlend, IsContinuousAcrossSampleBoundariesAndClampedAtTheEnds) {
  const int samples = 8;
  // The effective weight of each slice, as a function of θₒ.
  auto weights = [&](float theta) {
    const shared::SliceBlend b = shared::sliceBlendAt(theta, samples, 1u);
    std::vector<double> w(samples, 0.0);
    w[b.first] += 1.0 - b.weight;
    w[b.second] += b.weight;
    return w;
  };
  const double step = (kPi / 2.0) / samples;
  for (int t = 0; t <= samples; ++t) {
    for (double at : {t * step, (t + 0.5) * step}) {  // cell boundaries and sample centres
      const auto below = weights(static_cast<float>(at - 1e-4)), above = weights(static_cast<float>(at + 1e-4));
      for (int s = 0; s < samples; ++s) EXPECT_NEAR(below[s], above[s], 2e-3) << "θₒ " << at << ", slice " << s;
    }
  }
  EXPECT_EQ(shared::sliceBlendAt(0.0f, samples, 1u).first, 0u);
  EXPECT_EQ(shared::sliceBlendAt(0.0f, samples, 1u).weight, 0.0f);
  const shared::SliceBlend top = shared::sliceBlendAt(2.0f, samples, 1u);  // beyond π/2
  EXPECT_EQ(top.first, static_cast<shared::uint>(samples - 1));
  EXPECT_EQ(top.second, static_cast<shared::uint>(samples - 1));
}

TEST(SliceBlend, NearestMatchesTheTablesNearestSlice) {
  const BrdfSliceTable table = BrdfSliceTable::build(*makeLambert({0.5, 0.5, 0.5}), {2, 16, 1});
  for (int k = 0; k <= 200; ++k) {
    const double theta = k * (kPi / 2.0) / 200.0 + 1e-6;  // off the cell edges, where float and double may split
    EXPECT_EQ(shared::sliceBlendAt(static_cast<float>(theta), 16u, 0u).first, static_cast<shared::uint>(table.nearestSlice(theta)))
        << theta;
  }
}

TEST(Fused, RefusesMixedLevelsAndLevelsOutOfRange) {
  std::mt19937 rng(9u);
  const Case c = randomCase(4, false, rng);
  const PixelSlices slices = PixelSlices::synthesize(c.table);
  std::array<SparseHaar, 3> other;
  for (auto& l : other) l = randomSparse(5, 8, -1, 1, rng);
  const FusedLight wrongLight = FusedLight::synthesize(other);
  FusedScratch scratch;
  EXPECT_THROW(fusedShade(slices, {}, {}, wrongLight, weighted(c), scratch), std::invalid_argument);
  EXPECT_THROW(checkFusedLevel(1), std::invalid_argument);
  EXPECT_THROW(checkFusedLevel(8), std::invalid_argument);
  EXPECT_NO_THROW(checkFusedLevel(7));
}

}  // namespace
}  // namespace haarcast
