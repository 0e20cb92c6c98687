// `fused` with exact visibility bits and point lights (visibility_bits.h,
// light_split.h, fused.h): the blend against a brute-force sum, the bits path
// against the Haar-list path it replaces, a point light against the BRDF at
// its direction, and the light split's bookkeeping.
#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "haarcast/core/brdf.h"
#include "haarcast/core/fused.h"
#include "haarcast/core/light_split.h"
#include "haarcast/core/rotation.h"
#include "haarcast/core/visibility_bits.h"

namespace haarcast {
namespace {

std::vector<double> thetaOutLayout(int t) {
  std::vector<double> out;
  for (int k = 0; k < t; ++k) out.push_back((k + 0.5) * (kPi / 2.0) / t);
  return out;
}

BrdfSliceTable randomTable(int level, int thetaSamples, std::mt19937& rng) {
  std::uniform_real_distribution<double> dist(0.05, 1.0);
  std::vector<HaarMap> slices;
  for (int c = 0; c < 3; ++c) {
    for (int t = 0; t < thetaSamples; ++t) {
      SphereMap map(level);
      for (int i = 0; i < map.size(); ++i)
        for (int j = 0; j < map.size(); ++j) map.at(i, j) = i >= map.size() / 2 ? 0.0f : static_cast<float>(dist(rng));
      slices.push_back(forwardHaar(map));
    }
  }
  return BrdfSliceTable::fromSlices(thetaOutLayout(thetaSamples), std::move(slices));
}

// A light of random texels in [0, 0.2) per channel, as fused reads it.
FusedLight randomLight(int level, std::mt19937& rng) {
  std::array<SphereMap, 3> weighted;
  std::uniform_real_distribution<double> l(0.0, 0.2);
  for (auto& m : weighted) {
    m = SphereMap(level);
    for (float& x : m.values()) x = static_cast<float>(l(rng));
  }
  return FusedLight::fromWeightedMaps(weighted);
}

VisibilityBits randomBits(int level, std::size_t points, std::mt19937& rng) {
  VisibilityBits bits(level, points);
  std::bernoulli_distribution coin(0.6);
  for (std::size_t p = 0; p < points; ++p)
    for (std::size_t i = 0; i < bits.directions(); ++i)
      if (coin(rng)) bits.point(p)[i / 32] |= 1u << (i % 32);
  return bits;
}

// One pixel's random inputs at level 4: three θₒ slices, a light, three
// vertices' bits.
struct RandomPixel {
  explicit RandomPixel(unsigned seed)
      : rng(seed),
        table(randomTable(kLevel, 3, rng)),
        slices(PixelSlices::synthesize(table)),
        light(randomLight(kLevel, rng)),
        bits(randomBits(kLevel, 3, rng)) {}
  static constexpr int kLevel = 4;
  std::mt19937 rng;
  BrdfSliceTable table;
  PixelSlices slices;
  FusedLight light;
  VisibilityBits bits;
};

TEST(VisibilityBits, BlendIsTheWeightedSumOfTheBits) {
  std::mt19937 rng(3);
  for (int level : {2, 4, 5}) {
    const VisibilityBits bits = randomBits(level, 3, rng);
    const std::array<WeightedBits, 3> w = {WeightedBits{bits.point(0).data(), 0.2f},
                                           WeightedBits{bits.point(1).data(), 0.5f},
                                           WeightedBits{bits.point(2).data(), 0.3f}};
    std::vector<float> v(bits.directions());
    blendVisibility(w, level, v);
    for (std::size_t i = 0; i < bits.directions(); ++i) {
      const float want = 0.2f * bits.visible(0, i) + 0.5f * bits.visible(1, i) + 0.3f * bits.visible(2, i);
      ASSERT_FLOAT_EQ(v[i], want) << "level " << level << " direction " << i;
    }
  }
}

TEST(VisibilityBits, AssignRefusesStrayBitsAndWrongSizes) {
  VisibilityBits bits(2, 2);  // 16 directions in one word each
  EXPECT_THROW(bits.assign(std::vector<std::uint32_t>{1u}), std::invalid_argument);
  EXPECT_THROW(bits.assign(std::vector<std::uint32_t>{1u, 1u << 16}), std::invalid_argument);
  bits.assign(std::vector<std::uint32_t>{0xFFFFu, 1u});
  EXPECT_TRUE(bits.visible(0, 15));
  EXPECT_TRUE(bits.visible(1, 0));
  EXPECT_FALSE(bits.visible(1, 1));
  EXPECT_EQ(bits.map(1).at(0, 0), 1.0f);
  EXPECT_EQ(bits.map(1).at(0, 1), 0.0f);
}

// The bits path is the list path with nothing truncated: each vertex's bits
// Haar-coded whole give the same V, so the same sum.
TEST(FusedBits, EqualsTheListPathWithEveryCoefficientKept) {
  const RandomPixel pixel(7);
  const PixelSlices& slices = pixel.slices;
  const FusedLight& light = pixel.light;
  const VisibilityBits& bits = pixel.bits;
  std::array<SparseHaar, 3> lists;
  for (std::size_t v = 0; v < 3; ++v) lists[v] = keepLargest(forwardHaar(bits.map(v)), bits.directions());
  const std::array<float, 3> b = {0.25f, 0.35f, 0.4f};
  FusedScratch scratch;
  for (const EulerYXY r : {EulerYXY{0.3, 1.1, -0.7}, EulerYXY{2.0, 0.2, 4.0}}) {
    const shared::SliceBlend blend{0u, 1u, 0.3f};
    const std::array<WeightedBits, 3> wb = {WeightedBits{bits.point(0).data(), b[0]}, WeightedBits{bits.point(1).data(), b[1]},
                                            WeightedBits{bits.point(2).data(), b[2]}};
    const std::array<WeightedVisibility, 3> wl = {WeightedVisibility{&lists[0], b[0]}, WeightedVisibility{&lists[1], b[1]},
                                                  WeightedVisibility{&lists[2], b[2]}};
    const auto fromBits = fusedShade(slices, blend, r, light, wb, {}, 0u, scratch);
    const auto fromLists = fusedShade(slices, blend, r, light, wl, scratch);
    for (std::size_t c = 0; c < 3; ++c) EXPECT_NEAR(fromBits[c], fromLists[c], 1e-5 * std::abs(fromLists[c]) + 1e-6);
  }
}

// Directions about a slice's mirror direction (θ = θₒ, φ = π), off the
// texel centres: θ and φ each over ±span in steps, in degrees.
struct LobeSweep {
  double thetaSpan, thetaStep, phiSpan, phiStep;
};

// The sky other objects hide is taken off the sum a pixel keeps (FusedSum),
// before the point lights: a pixel given its parents' sum takes their
// hidden sky with it and reads none of its own, and one that sums its own
// shows what it showed before, max(0, S + lights − power·E/π).
TEST(FusedBits, TheHiddenSkyIsTakenOffTheSumAPixelKeeps) {
  const RandomPixel pixel(17);
  const PixelSlices& slices = pixel.slices;
  const FusedLight& light = pixel.light;
  const VisibilityBits& bits = pixel.bits;
  const std::array<WeightedBits, 3> wb = {WeightedBits{bits.point(0).data(), 0.2f}, WeightedBits{bits.point(1).data(), 0.3f},
                                          WeightedBits{bits.point(2).data(), 0.5f}};
  FusedPointLight sun;
  sun.direction = glm::normalize(glm::vec3(0.2f, 1.0f, 0.1f));
  sun.power = {0.3f, 0.2f, 0.1f};
  const shared::SliceBlend blend{1u, 2u, 0.25f};
  const EulerYXY r{0.3, 0.4, -0.7};
  FusedScratch scratch;
  FusedSum open, less;
  const auto plain = fusedShade(slices, blend, r, light, wb, std::span(&sun, 1), 1u, scratch, nullptr, nullptr, &open);
  const std::array<float, 3> hidden = {0.05f, 0.02f, 0.01f};
  const auto shaded = fusedShade(slices, blend, r, light, wb, std::span(&sun, 1), 1u, scratch, nullptr, &hidden, &less);
  for (std::size_t c = 0; c < 3; ++c) {
    const float e = slices.energy(1)[c] + 0.25f * (slices.energy(2)[c] - slices.energy(1)[c]);
    const float off = hidden[c] * e / static_cast<float>(kPi);
    ASSERT_GT(off, 1e-4f * plain[c]) << "channel " << c;
    EXPECT_NEAR(less.value[c], open.value[c] - off, 1e-6f * (1.0f + open.value[c])) << "channel " << c;
    EXPECT_NEAR(shaded[c], std::max(0.0f, plain[c] - off), 1e-6f * (1.0f + plain[c])) << "channel " << c;
  }
  // Given that sum, the pixel reads no hidden sky of its own (a different
  // one changes nothing) and shows what summing it showed.
  const std::array<float, 3> other = {5.0f, 5.0f, 5.0f};
  FusedSum given{less.value, true};
  const auto taken = fusedShade(slices, blend, r, light, wb, std::span(&sun, 1), 1u, scratch, nullptr, &other, &given);
  for (std::size_t c = 0; c < 3; ++c) EXPECT_EQ(taken[c], shaded[c]) << "channel " << c;
  // A sky hidden past the sum leaves a negative kept sum and nothing below zero shown.
  FusedSum dark;
  const auto none = fusedShade(slices, blend, r, light, wb, std::span(&sun, 1), 0u, scratch, nullptr, &other, &dark);
  for (std::size_t c = 0; c < 3; ++c) {
    EXPECT_LT(dark.value[c], 0.0f) << "channel " << c;
    EXPECT_EQ(none[c], 0.0f) << "channel " << c;
  }
}

// The relative L2 against the BRDF itself of a point light's ρ over a
// sweep of the lobe, the slices at `level` and their point slices at
// `pointLevel`, the pixel turned by `r` (so γ's column offset is taken at
// each table's own level). A hidden light adds nothing (checked).
double pointLightError(const Brdf& brdf, int level, int pointLevel, const EulerYXY& r, const LobeSweep& sweep) {
  SliceTableOptions options;
  options.level = level;
  options.thetaSamples = 4;
  const BrdfSliceTable table = BrdfSliceTable::build(brdf, options);
  options.level = pointLevel;
  const std::optional<BrdfSliceTable> fine =
      pointLevel != level ? std::optional(BrdfSliceTable::build(brdf, options)) : std::nullopt;
  const PixelSlices slices = PixelSlices::synthesize(table, fine ? &*fine : nullptr);
  EXPECT_EQ(slices.pointLevel(), pointLevel);
  const int t = 2;  // θₒ = 56.25°
  const glm::dvec3 wo = sphericalToDirection(table.thetaOut(t), 0.0);
  VisibilityBits open(level, 1);
  const std::array<WeightedBits, 1> v = {WeightedBits{open.point(0).data(), 1.0f}};
  const std::array<SphereMap, 3> empty{SphereMap(level), SphereMap(level), SphereMap(level)};
  const FusedLight dark = FusedLight::fromWeightedMaps(empty);
  const shared::SliceBlend blend{static_cast<shared::uint>(t), static_cast<shared::uint>(t), 0.0f};
  const glm::dmat3 turn = rotationMatrix(r);  // the slice's frame → the object's
  FusedScratch scratch;
  double squaredError = 0.0, squaredTruth = 0.0;
  for (double dTheta = -sweep.thetaSpan; dTheta <= sweep.thetaSpan; dTheta += sweep.thetaStep) {
    for (double dPhi = -sweep.phiSpan; dPhi <= sweep.phiSpan; dPhi += sweep.phiStep) {
      const double theta = table.thetaOut(t) + dTheta * kPi / 180.0;
      if (theta <= 0.02 || theta >= kPi / 2.0) continue;
      const glm::dvec3 wi = sphericalToDirection(theta, kPi + dPhi * kPi / 180.0);
      FusedPointLight point;
      point.direction = glm::vec3(turn * wi);
      point.power = {1.0f, 1.0f, 1.0f};
      const auto lit = fusedShade(slices, blend, r, dark, v, std::span(&point, 1), 1u, scratch);
      const auto hidden = fusedShade(slices, blend, r, dark, v, std::span(&point, 1), 0u, scratch);
      EXPECT_EQ(hidden[1], 0.0f);
      const double truth = brdf.evaluate(wi, wo).y * wi.y;
      squaredError += (lit[1] - truth) * (lit[1] - truth);
      squaredTruth += truth * truth;
    }
  }
  return std::sqrt(squaredError / squaredTruth);
}

// A point light is ρ at its direction: the point slices (each texel's mean
// less a 24th of its Laplacian) read by Catmull-Rom come within 3.0 %
// (relative L2) of the BRDF itself over a ggx:0.3 lobe at level 5. The
// same cubic over the means is 3.9 % off, and the map's bilinear lookup
// of the means 6.6 % (high on the tail, low at the peak). Hidden, it adds
// nothing.
TEST(FusedBits, APointLightIsTheBrdfAtItsDirection) {
  const std::unique_ptr<Brdf> ggx = makeGgx(glm::dvec3(0.05), glm::dvec3(0.9), 0.3);
  const EulerYXY identity{0.0, 0.0, 0.0};  // the slice's frame is the object's
  EXPECT_LT(pointLightError(*ggx, 5, 5, identity, {30.0, 1.7, 40.0, 2.3}), 0.035);
}

// A lobe a few texels wide is read off its peak from its own level's point
// slices: ggx:0.1 at level 6 (its median angle about 4 texels), turned by
// a pixel's rotation, is 10.0 % off the BRDF from level-6 point slices and
// 1.05 % from level 7's (render::pointLightLevel's choice for it), over its
// bulk. Taking γ's column offset at the pass's level instead of the finer
// table's puts the lobe columns away: far over either.
TEST(FusedBits, PointLightsReadANarrowLobeFromAFinerTable) {
  const std::unique_ptr<Brdf> ggx = makeGgx(glm::dvec3(0.05), glm::dvec3(0.9), 0.1);
  const EulerYXY r{0.7, 0.4, 2.31};
  const LobeSweep bulk{12.0, 12.0 / 17.3, 12.0, 12.0 / 13.1};
  const double own = pointLightError(*ggx, 6, 6, r, bulk);
  const double finer = pointLightError(*ggx, 6, 7, r, bulk);
  std::printf("ggx:0.1 point lights, level 6: %.2f %% from level-6 point slices, %.2f %% from level 7's\n", 100.0 * own,
              100.0 * finer);
  EXPECT_LT(finer, 0.02);
  EXPECT_LT(finer, 0.3 * own);
}

// The split keeps every bit of energy: lights + rest = the map, channel by
// channel, and a small sun is found where it is.
TEST(LightSplit, FindsASmallSunAndLosesNothing) {
  const int level = 6;
  const glm::dvec3 sun = glm::normalize(glm::dvec3(0.3, 0.8, -0.5));
  std::array<SphereMap, 3> light;
  for (std::size_t c = 0; c < 3; ++c) {
    light[c] = SphereMap::fromFunction(level, [&](const glm::dvec3& d) {
      const double sky = 0.2 + 0.1 * d.y;
      return glm::dot(d, sun) > std::cos(2.0 * kPi / 180.0) ? 5000.0 * (1.0 + 0.1 * static_cast<double>(c)) : sky;
    });
  }
  LightSplitOptions whole;
  whole.parts = 1;
  const LightSplit split = splitLight(light, whole);
  ASSERT_EQ(split.lights.size(), 1u);
  // Within a third of a level-6 texel (2.8°): the power-weighted centre of
  // the texels the sun covers.
  EXPECT_GT(glm::dot(split.lights[0].direction, sun), std::cos(1.0 * kPi / 180.0));
  for (std::size_t c = 0; c < 3; ++c) {
    double total = 0.0, rest = 0.0;
    for (int r = 0; r < mapSize(level); ++r) {
      for (int col = 0; col < mapSize(level); ++col) {
        total += light[c].at(r, col) * pixelSolidAngle(level, r);
        rest += split.rest[c].at(r, col) * pixelSolidAngle(level, r);
      }
    }
    EXPECT_NEAR(rest + split.lights[0].power[c], total, 1e-6 * total);
    EXPECT_GT(split.lights[0].power[c], 0.5 * total) << "the sun carries most of this sky's power";
  }
  // In parts: the same power and rest, the parts' power-weighted mean
  // direction the whole's, each part inside the sun (2°) and off its centre.
  const LightSplit quarters = splitLight(light);
  // (The sun covers a few level-6 texels: some quadrants may hold none.)
  ASSERT_GE(quarters.lights.size(), 2u);
  ASSERT_LE(quarters.lights.size(), 4u);
  glm::dvec3 mean(0.0);
  std::array<double, 3> sum{};
  for (const DirectionalLight& q : quarters.lights) {
    const double cosine = glm::dot(q.direction, split.lights[0].direction);
    EXPECT_LT(cosine, std::cos(0.2 * kPi / 180.0));
    EXPECT_GT(cosine, std::cos(2.0 * kPi / 180.0));
    mean += luminance709(q.power[0], q.power[1], q.power[2]) * q.direction;
    for (std::size_t c = 0; c < 3; ++c) sum[c] += q.power[c];
  }
  EXPECT_GT(glm::dot(glm::normalize(mean), split.lights[0].direction), std::cos(0.01 * kPi / 180.0));
  for (std::size_t c = 0; c < 3; ++c) {
    EXPECT_NEAR(sum[c], split.lights[0].power[c], 1e-9 * sum[c]);
    EXPECT_EQ(quarters.rest[c].values()[100], split.rest[c].values()[100]);
  }
  LightSplitOptions none;
  none.maxLights = 0;
  EXPECT_TRUE(splitLight(light, none).lights.empty());
  LightSplitOptions tooMany;
  tooMany.maxLights = 33;
  EXPECT_THROW(splitLight(light, tooMany), std::invalid_argument);
}

// A sun of 1° radius placed inside one level-6 texel, off its centre: split
// on that map its light sits at the texel's centre, on a level-9 map of the
// same sky within a tenth of a degree; and the coarse rest plus the light
// still hold all the power.
TEST(LightSplit, OnAFinerMapTheSunIsWhereItIsAndNothingIsLost) {
  // θ = 45.7°, φ = 32.9°: a level-6 texel spans 2.8° × 5.6° and is centred
  // at (46.4°, 33.75°), so the sun lies 1.0° from its texel's centre.
  const glm::dvec3 sun = sphericalToDirection(45.7 * kPi / 180.0, 32.9 * kPi / 180.0);
  auto sky = [&](int level) {
    std::array<SphereMap, 3> light;
    for (std::size_t c = 0; c < 3; ++c)
      light[c] = supersampledMap(level, level >= 9 ? 2 : 16, [&](const glm::dvec3& d) {
        return glm::dot(d, sun) > std::cos(1.0 * kPi / 180.0) ? 20000.0 : 0.3 + 0.1 * d.y;
      });
    return light;
  };
  const std::array<SphereMap, 3> coarse = sky(6), fine = sky(9);
  LightSplitOptions whole;
  whole.parts = 1;
  const LightSplit onCoarse = splitLight(coarse, whole);
  const LightSplit onFine = splitLight(fine, 6, whole);
  ASSERT_EQ(onCoarse.lights.size(), 1u);
  ASSERT_EQ(onFine.lights.size(), 1u);
  const double coarseOff = std::acos(std::min(1.0, glm::dot(onCoarse.lights[0].direction, sun))) * 180.0 / kPi;
  const double fineOff = std::acos(std::min(1.0, glm::dot(onFine.lights[0].direction, sun))) * 180.0 / kPi;
  EXPECT_GT(coarseOff, 0.5) << "the coarse texel's centre is off the sun";
  EXPECT_LT(fineOff, 0.1);
  ASSERT_EQ(onFine.rest[0].level(), 6);
  for (std::size_t c = 0; c < 3; ++c) {
    EXPECT_NEAR(onFine.rest[c].integral() + onFine.lights[0].power[c], fine[c].integral(), 1e-5 * fine[c].integral());
  }
  EXPECT_THROW(splitLight(coarse, 7), std::invalid_argument) << "the rest cannot be finer than the map";
}

TEST(SphereMap, DownsampledIsTheSolidAngleMeanAndKeepsTheIntegral) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 2.0f);
  SphereMap fine(5);
  for (float& v : fine.values()) v = u(rng);
  const SphereMap coarse = fine.downsampled(3);
  ASSERT_EQ(coarse.level(), 3);
  EXPECT_NEAR(coarse.integral(), fine.integral(), 1e-5 * fine.integral());
  // One pixel by brute force: the 4×4 fine pixels it covers, by solid angle.
  double sum = 0.0, solid = 0.0;
  for (int r = 4; r < 8; ++r)
    for (int c = 20; c < 24; ++c) sum += fine.at(r, c) * pixelSolidAngle(5, r), solid += pixelSolidAngle(5, r);
  EXPECT_NEAR(coarse.at(1, 5), sum / solid, 1e-5);
  EXPECT_EQ(fine.downsampled(5).values()[7], fine.values()[7]);
  EXPECT_THROW((void)fine.downsampled(6), std::invalid_argument);
}

}  // namespace
}  // namespace haarcast
