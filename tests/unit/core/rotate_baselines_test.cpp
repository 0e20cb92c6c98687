// The two precomputing baselines, `matrix` (Wang et al. 2006) and `table`
// (Ng et al. 2004), against `spatial`, whose rotations define both.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "haarcast/core/rotation.h"

namespace haarcast {
namespace {

// A map with every coefficient non-zero, so that every matrix column and every
// pixel of the table's copies is exercised.
HaarMap randomMap(int level, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  HaarMap f(level);
  for (float& c : f.coefficients()) c = u(rng);
  return f;
}

// A smooth glossy lobe about a tilted axis: the kind of slice the baselines
// interpolate between samples of.
HaarMap lobeMap(int level) {
  const glm::dvec3 axis = sphericalToDirection(0.7, 1.1);
  return forwardHaar(SphereMap::fromFunction(level, [&](const glm::dvec3& d) {
    const double c = d.x * axis.x + d.y * axis.y + d.z * axis.z;
    return c > 0.0 ? std::pow(c, 8.0) : 0.0;
  }));
}

double pixelAngle(int level) { return kTwoPi / mapSize(level); }

// Largest |a − b| relative to the largest |b|.
double relativeMaxError(const HaarMap& a, const HaarMap& b) {
  double diff = 0.0, scale = 0.0;
  for (std::size_t i = 0; i < b.coefficientCount(); ++i) {
    diff = std::max(diff, std::abs(double{a[i]} - b[i]));
    scale = std::max(scale, std::abs(double{b[i]}));
  }
  return diff / scale;
}

// Root-mean-square difference relative to the RMS of b.
double relativeRmsError(const HaarMap& a, const HaarMap& b) {
  double diff = 0.0, norm = 0.0;
  for (std::size_t i = 0; i < b.coefficientCount(); ++i) {
    diff += (double{a[i]} - b[i]) * (double{a[i]} - b[i]);
    norm += double{b[i]} * b[i];
  }
  return std::sqrt(diff / norm);
}

// f shifted by a whole number of pixels along φ, done on the pixels directly:
// g(θ, φ) = f(θ, φ − pixels·2π/M).
HaarMap permutedPhi(const HaarMap& f, int pixels) {
  const SphereMap src = inverseHaar(f);
  const int m = src.size();
  SphereMap g(src.level());
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) g.at(i, j) = src.at(i, ((j - pixels) % m + m) % m);
  return forwardHaar(g);
}

HaarMap rotated(const SliceRotator& rotator, std::size_t slice, const EulerYXY& r) {
  HaarMap out;
  rotator.rotate(slice, r, out);
  return out;
}

// Rounding of float maps through two transforms and a resampling.
constexpr double kFloatTolerance = 2e-6;

// ---- (a) at their own samples the baselines are `spatial` -------------------

TEST(MatrixRotator, EqualsSpatialAtEverySampleElevationWithoutThreshold) {
  for (int level : {3, 4}) {
    const HaarMap f = randomMap(level, 7);
    RotatorOptions options;
    options.matrixElevations = 9;
    options.matrixThreshold = 0.0;
    const auto rotator = makeRotator(RotationMethod::Matrix, {f}, options);
    const double px = pixelAngle(level);
    for (int k = 0; k < options.matrixElevations; ++k) {
      const EulerYXY r{3 * px, kPi * k / (options.matrixElevations - 1), 5 * px};
      EXPECT_LT(relativeMaxError(rotated(*rotator, 0, r), rotateSpatial(f, r)), kFloatTolerance)
          << "level " << level << " elevation sample " << k;
    }
  }
}

TEST(MatrixRotator, EqualsSpatialAtSampleElevationsAtLevel5) {
  const int level = 5;
  const HaarMap f = randomMap(level, 8);
  RotatorOptions options;
  options.matrixThreshold = 0.0;  // default 33 elevations
  const auto rotator = makeRotator(RotationMethod::Matrix, {f}, options);
  const double px = pixelAngle(level);
  for (int k : {1, 10, 16, 27, 32}) {
    const EulerYXY r{-7 * px, kPi * k / 32, 12 * px};
    EXPECT_LT(relativeMaxError(rotated(*rotator, 0, r), rotateSpatial(f, r)), kFloatTolerance) << "sample " << k;
  }
}

TEST(MatrixRotator, DefaultThresholdStaysCloseToSpatialAtSamples) {
  const int level = 5;
  const double px = pixelAngle(level);
  for (const HaarMap& f : {randomMap(level, 9), lobeMap(level)}) {
    const auto rotator = makeRotator(RotationMethod::Matrix, {f});
    for (int k : {3, 16, 29}) {
      const EulerYXY r{2 * px, kPi * k / 32, -4 * px};
      // Dropping entries below 1e-4 of the largest leaves errors of a few
      // 1e-4 of the map's largest coefficient (measured over all 33 samples:
      // at most 4.8e-4 for a random map, 6e-5 at level 3).
      EXPECT_LT(relativeMaxError(rotated(*rotator, 0, r), rotateSpatial(f, r)), 1e-3) << "sample " << k;
    }
  }
}

TEST(MatrixRotator, InterpolatesLinearlyBetweenNeighbouringSamples) {
  const int level = 4;
  const HaarMap f = randomMap(level, 10);
  RotatorOptions options;
  options.matrixElevations = 9;
  options.matrixThreshold = 0.0;
  const auto rotator = makeRotator(RotationMethod::Matrix, {f}, options);
  const double px = pixelAngle(level);
  const double step = kPi / 8;
  for (int k : {0, 3, 7}) {
    const double t = 0.3;
    const EulerYXY r{px, (k + t) * step, 6 * px};
    const HaarMap lower = rotateSpatial(f, {r.alpha, k * step, r.gamma});
    const HaarMap upper = rotateSpatial(f, {r.alpha, (k + 1) * step, r.gamma});
    HaarMap expected(level);
    for (std::size_t i = 0; i < expected.coefficientCount(); ++i)
      expected[i] = static_cast<float>((1.0 - t) * lower[i] + t * upper[i]);
    EXPECT_LT(relativeMaxError(rotated(*rotator, 0, r), expected), kFloatTolerance) << "between " << k << ", " << k + 1;
  }
}

TEST(MatrixRotator, AcceptsElevationsOutsideZeroToPi) {
  const int level = 4;
  const HaarMap f = randomMap(level, 11);
  RotatorOptions options;
  options.matrixElevations = 9;
  options.matrixThreshold = 0.0;
  const auto rotator = makeRotator(RotationMethod::Matrix, {f}, options);
  const double px = pixelAngle(level);
  for (double beta : {-kPi * 3 / 8, -kPi, kPi * 3 / 8 + kTwoPi, kPi * 13 / 8}) {
    const EulerYXY r{2 * px, beta, -3 * px};
    EXPECT_LT(relativeMaxError(rotated(*rotator, 0, r), rotateSpatial(f, r)), kFloatTolerance) << "β = " << beta;
  }
}

TEST(TableRotator, EqualsSpatialAtEveryGridRotation) {
  const int level = 4;
  const HaarMap f = randomMap(level, 12);
  RotatorOptions options;
  options.tableElevations = 5;
  options.tableSpins = 8;
  const auto rotator = makeRotator(RotationMethod::Table, {f}, options);
  const double px = pixelAngle(level);
  for (int k = 0; k < options.tableElevations; ++k) {
    for (int j = 0; j < options.tableSpins; ++j) {
      const EulerYXY r{3 * px, kPi * k / 4, kTwoPi * j / 8};
      EXPECT_LT(relativeMaxError(rotated(*rotator, 0, r), rotateSpatial(f, r)), kFloatTolerance)
          << "grid (" << k << ", " << j << ")";
    }
  }
}

TEST(TableRotator, LooksUpTheNearestElevationAndSpin) {
  const int level = 4;
  const std::vector<HaarMap> slices = {randomMap(level, 13), randomMap(level, 14)};
  RotatorOptions options;
  options.tableElevations = 5;
  options.tableSpins = 8;
  const auto rotator = makeRotator(RotationMethod::Table, slices, options);
  const double px = pixelAngle(level);
  const double betaStep = kPi / 4, gammaStep = kTwoPi / 8;
  struct Case {
    EulerYXY r;
    EulerYXY grid;  // the grid rotation it must snap to
  };
  const Case cases[] = {
      {{2 * px, 1.3 * betaStep, 2.4 * gammaStep}, {2 * px, betaStep, 2 * gammaStep}},
      {{-px, 2.6 * betaStep, 5.6 * gammaStep}, {-px, 3 * betaStep, 6 * gammaStep}},
      {{5 * px, 0.7 * betaStep, 7.8 * gammaStep}, {5 * px, betaStep, 0.0}},          // γ wraps to 0
      {{0.0, 1.2 * betaStep, -0.3 * gammaStep}, {0.0, betaStep, 0.0}},               // negative γ
      {{4 * px, 3.8 * betaStep, 1.1 * gammaStep - kTwoPi}, {4 * px, kPi, gammaStep}},  // γ beyond −2π
  };
  for (std::size_t s = 0; s < slices.size(); ++s) {
    for (const Case& c : cases) {
      EXPECT_LT(relativeMaxError(rotated(*rotator, s, c.r), rotateSpatial(slices[s], c.grid)), kFloatTolerance)
          << "slice " << s << " β " << c.r.beta << " γ " << c.r.gamma;
    }
  }
}

TEST(TableRotator, CanonicalisesEulerTriplesOfOneRotation) {
  // (α, −β, γ) and (α + π, β, γ − π) are one rotation; at the pole the split
  // of the turn between α and γ is arbitrary. Each must find the same copy.
  const int level = 4;
  const HaarMap f = randomMap(level, 15);
  RotatorOptions options;
  options.tableSpins = 4;  // 4 pixels apart at level 4: a 1-pixel γ would snap away
  const auto rotator = makeRotator(RotationMethod::Table, {f}, options);
  const double px = pixelAngle(level);
  const double betaStep = kPi / 8;
  // (3, −2·step, 4) pixels is the grid rotation (3 + 8, 2·step, 4 − 8) pixels.
  const EulerYXY negative{3 * px, -2 * betaStep, 4 * px};
  EXPECT_LT(relativeMaxError(rotated(*rotator, 0, negative), rotateSpatial(f, negative)), kFloatTolerance);
  EXPECT_LT(relativeMaxError(rotated(*rotator, 0, {2 * px, 0.0, px}), permutedPhi(f, 3)), kFloatTolerance)
      << "γ + α at β = 0 is one φ-shift, not a γ snap";
  EXPECT_LT(relativeMaxError(rotated(*rotator, 0, {2 * px, kPi, px}), rotateSpatial(f, {px, kPi, 0.0})),
            kFloatTolerance)
      << "at β = π the turn is α − γ";
}

// ---- (b) zero rotation, (c) whole-pixel φ-shifts ----------------------------

TEST(Baselines, ZeroRotationIsTheIdentity) {
  for (int level : {3, 5}) {
    const HaarMap f = randomMap(level, 16);
    for (RotationMethod m : {RotationMethod::Matrix, RotationMethod::Table}) {
      const auto rotator = makeRotator(m, {f});
      EXPECT_LT(relativeMaxError(rotated(*rotator, 0, {}), f), kFloatTolerance)
          << methodName(m) << " level " << level;
    }
  }
}

TEST(Baselines, WholePixelPhiShiftsArePixelPermutations) {
  const int level = 4;
  const HaarMap f = randomMap(level, 17);
  const double px = pixelAngle(level);
  for (RotationMethod m : {RotationMethod::Matrix, RotationMethod::Table}) {
    const auto rotator = makeRotator(m, {f});
    for (int a : {1, 5, -3}) {
      for (int g : {0, 2, 7}) {
        EXPECT_LT(relativeMaxError(rotated(*rotator, 0, {a * px, 0.0, g * px}), permutedPhi(f, a + g)),
                  kFloatTolerance)
            << methodName(m) << " α " << a << " γ " << g << " pixels";
      }
    }
  }
}

// ---- (d) between samples, finer sampling is closer to `spatial` -------------

// Mean relative RMS error against `spatial` over fixed rotations whose β (and
// γ, for the table) fall between samples; α and γ are whole pixels for the
// matrix method so that only the β interpolation is measured.
double meanErrorBetweenSamples(RotationMethod m, const RotatorOptions& options, int level) {
  const HaarMap f = lobeMap(level);
  const auto rotator = makeRotator(m, {f}, options);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::uniform_int_distribution<int> pixel(0, mapSize(level) - 1);
  const double px = pixelAngle(level);
  double sum = 0.0;
  const int trials = 12;
  for (int t = 0; t < trials; ++t) {
    const double alpha = pixel(rng) * px;
    const double beta = (0.1 + 0.8 * u(rng)) * kPi;
    const double gamma = m == RotationMethod::Matrix ? pixel(rng) * px : u(rng) * kTwoPi;
    const EulerYXY r{alpha, beta, gamma};
    sum += relativeRmsError(rotated(*rotator, 0, r), rotateSpatial(f, r));
  }
  return sum / trials;
}

TEST(MatrixRotator, ErrorBetweenSamplesShrinksWithFinerElevationSampling) {
  const int level = 5;
  RotatorOptions coarse, fine;
  coarse.matrixElevations = 9;
  fine.matrixElevations = 33;
  const double coarseError = meanErrorBetweenSamples(RotationMethod::Matrix, coarse, level);
  const double fineError = meanErrorBetweenSamples(RotationMethod::Matrix, fine, level);
  // Linear interpolation of a smooth lobe: the error falls with the square of
  // the step (measured: 0.090 → 0.0051, 18×).
  EXPECT_LT(fineError, coarseError / 8.0) << "coarse " << coarseError << " fine " << fineError;
  EXPECT_GT(coarseError, 1e-3) << "between samples the interpolation must show";
}

TEST(TableRotator, ErrorBetweenSamplesShrinksWithFinerGrid) {
  const int level = 5;
  RotatorOptions coarse, fine;
  coarse.tableElevations = 5;
  coarse.tableSpins = 8;
  fine.tableElevations = 33;
  fine.tableSpins = 64;
  const double coarseError = meanErrorBetweenSamples(RotationMethod::Table, coarse, level);
  const double fineError = meanErrorBetweenSamples(RotationMethod::Table, fine, level);
  // A nearest lookup errs by up to half a step (measured: 0.36 → 0.059).
  EXPECT_LT(fineError, coarseError / 3.0) << "coarse " << coarseError << " fine " << fineError;
}

// ---- (e) storage ------------------------------------------------------------

TEST(TableRotator, StoresOneCopyPerSliceElevationAndSpin) {
  const int level = 3;
  const std::size_t mapBytes = 64 * sizeof(float);
  for (std::size_t slices : {1u, 3u}) {
    for (auto [elevations, spins] : {std::pair{2, 1}, std::pair{5, 8}, std::pair{9, 16}}) {
      RotatorOptions options;
      options.tableElevations = elevations;
      options.tableSpins = spins;
      const auto rotator =
          makeRotator(RotationMethod::Table, std::vector<HaarMap>(slices, randomMap(level, 18)), options);
      EXPECT_EQ(rotator->storedBytes(), slices * static_cast<std::size_t>(elevations * spins) * mapBytes)
          << slices << " slices, " << elevations << "×" << spins;
    }
  }
}

TEST(MatrixRotator, StorageGrowsWithElevationsNotWithSlices) {
  const int level = 4;
  const std::size_t mapBytes = 256 * sizeof(float);
  auto matrixBytes = [&](std::size_t slices, int elevations, double threshold) {
    RotatorOptions options;
    options.matrixElevations = elevations;
    options.matrixThreshold = threshold;
    const auto rotator =
        makeRotator(RotationMethod::Matrix, std::vector<HaarMap>(slices, randomMap(level, 19)), options);
    return rotator->storedBytes() - slices * mapBytes;
  };
  const std::size_t nine = matrixBytes(1, 9, 1e-4);
  EXPECT_EQ(matrixBytes(4, 9, 1e-4), nine) << "the matrices do not depend on the slices";
  // At least the row offsets, and less than dense.
  EXPECT_GT(nine, 9 * 257 * sizeof(std::uint32_t));
  EXPECT_LT(nine, 9 * 256 * 256 * 2 * sizeof(float));
  // The 33 elevations are a superset of the 9; the extra ones are about as
  // full, so storage grows about in proportion.
  const double ratio = static_cast<double>(matrixBytes(1, 33, 1e-4)) / static_cast<double>(nine);
  EXPECT_GT(ratio, 3.0);
  EXPECT_LT(ratio, 33.0 / 9.0 * 1.25);
  EXPECT_GE(matrixBytes(1, 9, 0.0), nine) << "a threshold only drops entries";
  EXPECT_LT(matrixBytes(1, 9, 1e-2), nine);
}

TEST(MatrixRotator, KeepsEntriesAboveThresholdTimesLargest) {
  // Rebuild each matrix from its definition, column c = rotateSpatial(e_c,
  // {0, β_k, 0}), and count what a threshold must keep: CSR holds N + 1 row
  // offsets and a (uint32 column, float value) pair per kept entry.
  const int level = 3;
  const std::size_t n = 64;
  for (double threshold : {0.01, 0.1}) {
    RotatorOptions options;
    options.matrixElevations = 3;
    options.matrixThreshold = threshold;
    std::size_t expected = n * sizeof(float);  // the one slice
    for (int k = 0; k < options.matrixElevations; ++k) {
      std::vector<HaarMap> columns;
      double largest = 0.0;
      for (std::size_t c = 0; c < n; ++c) {
        HaarMap e(level);
        e[c] = 1.0f;
        columns.push_back(rotateSpatial(e, {0.0, kPi * k / 2, 0.0}));
        for (float v : columns.back().coefficients()) largest = std::max(largest, std::abs(double{v}));
      }
      std::size_t kept = 0;
      for (const HaarMap& column : columns)
        for (float v : column.coefficients()) kept += std::abs(double{v}) >= threshold * largest ? 1 : 0;
      expected += (n + 1) * sizeof(std::uint32_t) + kept * (sizeof(std::uint32_t) + sizeof(float));
    }
    EXPECT_EQ(makeRotator(RotationMethod::Matrix, {randomMap(level, 20)}, options)->storedBytes(), expected)
        << "threshold " << threshold;
  }
}

// The elevation matrices depend on the level and options only: rotators of
// other slices (an object's three channels, other objects) share one copy,
// which sharedBytes() names so a scene counts it once.
TEST(Baselines, MatrixRotatorsShareTheirMatrices) {
  RotatorOptions options;
  options.matrixElevations = 3;
  const auto a = makeRotator(RotationMethod::Matrix, {randomMap(3, 1)}, options);
  const auto b = makeRotator(RotationMethod::Matrix, {randomMap(3, 2), randomMap(3, 3)}, options);
  const std::size_t mapBytes = HaarMap(3).coefficientCount() * sizeof(float);
  EXPECT_EQ(a->sharedBytes(), a->storedBytes() - mapBytes);
  EXPECT_EQ(b->sharedBytes(), a->sharedBytes());
  EXPECT_EQ(elevationMatrixViews(*a)[1].value.data(), elevationMatrixViews(*b)[1].value.data())
      << "the same level and options must share one set of matrices";
  options.matrixThreshold = 1e-2;
  const auto c = makeRotator(RotationMethod::Matrix, {randomMap(3, 1)}, options);
  EXPECT_NE(elevationMatrixViews(*c)[1].value.data(), elevationMatrixViews(*a)[1].value.data());
  EXPECT_LT(c->sharedBytes(), a->sharedBytes()) << "a higher threshold keeps fewer entries";
  EXPECT_EQ(makeRotator(RotationMethod::Haar, {randomMap(3, 1)})->sharedBytes(), 0u);
}

// ---- (f) bad input ----------------------------------------------------------

TEST(Baselines, RejectEmptySlicesAndBadOptions) {
  for (RotationMethod m : {RotationMethod::Matrix, RotationMethod::Table})
    EXPECT_THROW(makeRotator(m, {}), std::invalid_argument) << methodName(m);
  EXPECT_THROW(makeRotator(RotationMethod::Matrix, {HaarMap(3), HaarMap(4)}), std::invalid_argument);
  RotatorOptions options;
  options.matrixElevations = 1;
  EXPECT_THROW(makeRotator(RotationMethod::Matrix, {HaarMap(3)}, options), std::invalid_argument);
  options = {};
  options.matrixThreshold = -1.0;
  EXPECT_THROW(makeRotator(RotationMethod::Matrix, {HaarMap(3)}, options), std::invalid_argument);
  options = {};
  options.matrixElevations = 129;  // about 3.5 GB of matrices at level 8
  EXPECT_THROW(makeRotator(RotationMethod::Matrix, {HaarMap(8)}, options), std::invalid_argument);
  options = {};
  options.tableElevations = 1;
  EXPECT_THROW(makeRotator(RotationMethod::Table, {HaarMap(3)}, options), std::invalid_argument);
  options = {};
  options.tableSpins = 0;
  EXPECT_THROW(makeRotator(RotationMethod::Table, {HaarMap(3)}, options), std::invalid_argument);
  options = {};
  options.tableElevations = 65;
  options.tableSpins = 128;  // 8320 copies of a 1 MiB level-9 slice
  EXPECT_THROW(makeRotator(RotationMethod::Table, {HaarMap(9)}, options), std::invalid_argument);
}

TEST(Baselines, RejectSliceIndexOutOfRange) {
  HaarMap out;
  for (RotationMethod m : {RotationMethod::Matrix, RotationMethod::Table})
    EXPECT_THROW(makeRotator(m, {HaarMap(3)})->rotate(1, {}, out), std::out_of_range) << methodName(m);
}

}  // namespace
}  // namespace haarcast
