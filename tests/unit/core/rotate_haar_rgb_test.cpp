// rotateHaar3 and RgbHaarRotator: the three-channel path must give what
// three single-channel rotateHaar calls give, and allocate nothing once warm.
#include <array>
#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>
#include <vector>

#include <glm/vec3.hpp>
#include <gtest/gtest.h>

#include "../allocation_tracking.h"
#include "test_maps.h"

#include "haarcast/core/brdf.h"
#include "haarcast/core/brdf_slices.h"
#include "haarcast/core/rotate_haar.h"
#include "haarcast/core/triple_product.h"

namespace haarcast {
namespace {

using testing::maxAbs;
using testing::maxAbsDifference;

// Both paths compute in double and store float: they differ by double
// rounding before the final cast, a few float ulps of the largest coefficient.
constexpr double kTolerance = 1e-6;

// White noise per pixel: every coefficient non-zero, the hardest input.
HaarMap noiseMap(int level, std::mt19937& rng) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  SphereMap m(level);
  for (float& v : m.values()) v = u(rng);
  return forwardHaar(m);
}

// A glossy slice of one colour channel: smooth with a sharp lobe.
HaarMap glossySlice(int level, int channel) {
  const auto brdf = makePhong(glm::dvec3(0.1, 0.2, 0.3), glm::dvec3(0.9, 0.6, 0.4), 64.0);
  return forwardHaar(sliceMap(*brdf, 0.6, channel, level, 2));
}

std::array<HaarMap, 3> threeChannels(int level, bool noise, std::mt19937& rng) {
  if (noise) return {noiseMap(level, rng), noiseMap(level, rng), noiseMap(level, rng)};
  return {glossySlice(level, 0), glossySlice(level, 1), glossySlice(level, 2)};
}

void expectEqualToSingleChannel(const std::array<HaarMap, 3>& f, const EulerYXY& r, const HaarRotationOptions& o,
                                const std::array<HaarMap, 3>& got) {
  for (std::size_t c = 0; c < 3; ++c) {
    const HaarMap expected = rotateHaar(f[c], r, o);
    ASSERT_EQ(got[c].level(), expected.level());
    ASSERT_LE(maxAbsDifference(got[c], expected), kTolerance * maxAbs(expected))
        << "channel " << c << " rotation " << r.alpha << "," << r.beta << "," << r.gamma;
  }
}

TEST(RotateHaar3, EqualsThreeSingleChannelRotations) {
  std::mt19937 rng(5);
  HaarRotationScratch scratch;  // one scratch for every level: it must adapt both ways
  std::array<HaarMap, 3> out;
  for (int level : {7, 2, 3, 4, 5, 6}) {
    for (bool noise : {true, false}) {
      SCOPED_TRACE(::testing::Message() << "level " << level << (noise ? " noise" : " glossy"));
      const std::array<HaarMap, 3> f = threeChannels(level, noise, rng);
      const int count = level <= 5 ? 12 : (level == 6 ? 4 : 2);
      for (const EulerYXY& r : randomRotations(count, 300u + static_cast<unsigned>(level))) {
        rotateHaar3({&f[0], &f[1], &f[2]}, r, out, scratch);
        expectEqualToSingleChannel(f, r, {}, out);
      }
    }
  }
}

TEST(RotateHaar3, PolesAndSeam) {
  std::mt19937 rng(6);
  HaarRotationScratch scratch;
  std::array<HaarMap, 3> out;
  for (int level : {1, 5, 7}) {
    const std::array<HaarMap, 3> f = threeChannels(level, true, rng);
    for (const EulerYXY& r : {EulerYXY{}, EulerYXY{0, kPi, 0}, EulerYXY{0, kPi / 2, 0}, EulerYXY{kPi, 1e-9, 0},
                              EulerYXY{0.001, kPi - 0.01, -0.001}, EulerYXY{3.0, 0.02, 1.0}}) {
      rotateHaar3({&f[0], &f[1], &f[2]}, r, out, scratch);
      expectEqualToSingleChannel(f, r, {}, out);
    }
  }
}

TEST(RotateHaar3, RefinedStillEqualsSpatial) {
  HaarRotationScratch scratch;
  std::array<HaarMap, 3> out;
  std::mt19937 rng(1);
  for (int level : {3, 5}) {
    const std::array<HaarMap, 3> f = threeChannels(level, false, rng);
    for (const EulerYXY& r : randomRotations(6, 17)) {
      rotateHaar3({&f[0], &f[1], &f[2]}, r, out, scratch);
      for (std::size_t c = 0; c < 3; ++c) {
        const HaarMap s = rotateSpatial(f[c], r);
        EXPECT_LT(maxAbsDifference(out[c], s), 2e-5 * maxAbs(s)) << "level " << level << " channel " << c;
      }
    }
  }
}

TEST(RotateHaar3, CoarserStartLevelsAndOtherVariants) {
  std::mt19937 rng(7);
  HaarRotationScratch scratch;
  std::array<HaarMap, 3> out;
  const std::array<HaarMap, 3> f = threeChannels(6, false, rng);
  for (const HaarRotationOptions& o : {HaarRotationOptions{HaarVariant::Refined, 0}, HaarRotationOptions{HaarVariant::Refined, 2},
                                       HaarRotationOptions{HaarVariant::Refined, 4}, HaarRotationOptions{HaarVariant::Faithful, -1},
                                       HaarRotationOptions{HaarVariant::Local, 3}}) {
    SCOPED_TRACE(::testing::Message() << variantName(o.variant) << " start " << o.startLevel);
    for (const EulerYXY& r : randomRotations(3, 8)) {
      rotateHaar3({&f[0], &f[1], &f[2]}, r, out, scratch, o);
      expectEqualToSingleChannel(f, r, o, out);
    }
  }
}

TEST(RotateHaar3, LevelZeroMapsAreRotationInvariant) {
  std::array<HaarMap, 3> f{HaarMap(0), HaarMap(0), HaarMap(0)};
  f[1][0] = 2.0f;
  std::array<HaarMap, 3> out;
  HaarRotationScratch scratch;
  rotateHaar3({&f[0], &f[1], &f[2]}, {1, 2, 3}, out, scratch);
  EXPECT_EQ(out[1][0], 2.0f);
  EXPECT_EQ(out[0].level(), 0);
}

TEST(RotateHaar3, WarmCallAllocatesNothing) {
  std::mt19937 rng(9);
  const std::array<HaarMap, 3> f = threeChannels(5, true, rng);
  const std::vector<EulerYXY> rs = randomRotations(8, 10);
  HaarRotationScratch scratch;
  std::array<HaarMap, 3> out;
  rotateHaar3({&f[0], &f[1], &f[2]}, rs[0], out, scratch);  // warms the scratch and the outputs
  const testing::AllocationCounter counter;
  for (const EulerYXY& r : rs) rotateHaar3({&f[0], &f[1], &f[2]}, r, out, scratch);
  EXPECT_EQ(counter.count(), 0u);
}

TEST(RotateHaar3, BadInputsAreRefused) {
  std::mt19937 rng(2);
  const HaarMap a = noiseMap(3, rng), b = noiseMap(4, rng);
  HaarRotationScratch scratch;
  std::array<HaarMap, 3> out;
  EXPECT_THROW(rotateHaar3({&a, &a, &b}, {}, out, scratch), std::invalid_argument);
  EXPECT_THROW(rotateHaar3({&a, nullptr, &a}, {}, out, scratch), std::invalid_argument);
  EXPECT_THROW(rotateHaar3({&a, &a, &a}, {}, out, scratch, {HaarVariant::Refined, 3}), std::invalid_argument);
}

TEST(RgbHaarRotator, EqualsThePerChannelRotators) {
  std::mt19937 rng(4);
  const int level = 4;
  std::array<std::vector<HaarMap>, 3> slices;
  for (int t = 0; t < 3; ++t)
    for (std::size_t c = 0; c < 3; ++c) slices[c].push_back(noiseMap(level, rng));
  std::array<std::unique_ptr<SliceRotator>, 3> single;
  for (std::size_t c = 0; c < 3; ++c) single[c] = makeRotator(RotationMethod::Haar, slices[c]);
  const RgbHaarRotator rgb(slices);
  EXPECT_EQ(rgb.sliceCount(), 3u);
  EXPECT_EQ(rgb.level(), level);
  EXPECT_EQ(rgb.storedBytes(), single[0]->storedBytes() + single[1]->storedBytes() + single[2]->storedBytes());

  HaarRotationScratch scratch;
  std::array<HaarMap, 3> out;
  HaarMap expected;
  for (const EulerYXY& r : randomRotations(4, 11)) {
    for (std::size_t t = 0; t < 3; ++t) {
      rgb.rotate(t, r, out, scratch);
      for (std::size_t c = 0; c < 3; ++c) {
        single[c]->rotate(t, r, expected);
        EXPECT_LE(maxAbsDifference(out[c], expected), kTolerance * maxAbs(expected)) << "slice " << t << " channel " << c;
      }
    }
  }
  EXPECT_THROW(rgb.rotate(3, {}, out, scratch), std::out_of_range);
}

TEST(RgbHaarRotator, BadTablesAreRefused) {
  std::mt19937 rng(3);
  const HaarMap a = noiseMap(3, rng), b = noiseMap(4, rng);
  EXPECT_THROW(RgbHaarRotator({std::vector<HaarMap>{a}, {a}, {}}), std::invalid_argument);
  EXPECT_THROW(RgbHaarRotator({std::vector<HaarMap>{a}, {a, a}, {a}}), std::invalid_argument);
  EXPECT_THROW(RgbHaarRotator({std::vector<HaarMap>{a}, {b}, {a}}), std::invalid_argument);
  RotatorOptions o;
  o.haarStartLevel = 3;
  EXPECT_THROW(RgbHaarRotator({std::vector<HaarMap>{a}, {a}, {a}}, o), std::invalid_argument);
}

// One pixel's shading, end to end: the renderer's loop (per channel one
// rotation and three products blended with the barycentrics) against the
// lean calls (one three-channel rotation, the visibility merged, one product
// per channel with the prepared light).
TEST(HaarPixel, LeanPathEqualsTheOldLoop) {
  std::mt19937 rng(31);
  std::bernoulli_distribution visible(0.7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int level : {4, 5}) {
    std::array<std::vector<HaarMap>, 3> slices;
    std::array<SparseHaar, 3> light;
    std::array<PreparedLight, 3> prepared;
    for (std::size_t c = 0; c < 3; ++c) {
      for (int t = 0; t < 2; ++t) slices[c].push_back(glossySlice(level, static_cast<int>(c)));
      SphereMap env(level);
      for (float& v : env.values()) v = static_cast<float>(4.0 * u(rng) * u(rng));
      light[c] = keepLargest(forwardHaar(env.weightedBySolidAngle()), 256);
      prepared[c].assign(light[c]);
    }
    const RgbHaarRotator rgb(slices);
    HaarRotationScratch scratch;
    std::array<HaarMap, 3> rotated;
    SparseHaar merged;
    PreparedVisibility visibility;
    for (const EulerYXY& r : randomRotations(6, 40u + static_cast<unsigned>(level))) {
      std::array<SparseHaar, 3> vertex;
      for (SparseHaar& v : vertex) {
        SphereMap map(level);
        for (float& x : map.values()) x = visible(rng) ? 1.0f : 0.0f;
        v = keepLargest(forwardHaar(map), 64);
      }
      const double a = u(rng), b = (1.0 - a) * u(rng);
      const std::array<double, 3> w{a, b, 1.0 - a - b};

      rgb.rotate(1, r, rotated, scratch);
      mergeVisibility({&vertex[0], &vertex[1], &vertex[2]}, w, merged);
      visibility.assign(merged);
      for (std::size_t c = 0; c < 3; ++c) {
        const HaarMap old = rotateHaar(slices[c][1], r);
        double expected = 0.0;
        for (std::size_t k = 0; k < 3; ++k) expected += w[k] * tripleProduct(light[c], old, vertex[k]);
        EXPECT_NEAR(tripleProduct(prepared[c], rotated[c], visibility), expected, 1e-5 * std::abs(expected) + 1e-9)
            << "level " << level << " channel " << c;
      }
    }
  }
}

}  // namespace
}  // namespace haarcast
