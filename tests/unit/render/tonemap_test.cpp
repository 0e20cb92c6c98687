// The display transform (render/tonemap.h) against its formula evaluated
// directly in double, and auto exposure against hand-computed values.
#include "haarcast/render/tonemap.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace haarcast::render {
namespace {

// The formula of tonemap.h written out: gain, Reinhard's extended curve,
// clamp, IEC 61966-2-1, rounding.
int directByte(double linear, double stops) {
  const double x = linear * std::exp2(stops);
  if (!(x > 0.0)) return 0;
  const double w2 = kToneWhite * kToneWhite;
  const double y = std::min(1.0, x * (1.0 + x / w2) / (1.0 + x));
  const double s = y <= 0.0031308 ? 12.92 * y : 1.055 * std::pow(y, 1.0 / 2.4) - 0.055;
  return static_cast<int>(std::lround(s * 255.0));
}

TEST(Tonemap, BytesAreTheFormulaExceptAtFloatRoundingOfACodeBoundary) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> logValue(-12.0, 5.0);
  for (const double stops : {-3.0, 0.0, 1.5}) {
    const auto thresholds = tonemapThresholds(stops);
    int exact = 0, total = 0;
    for (int i = 0; i < 20000; ++i) {
      const float v = static_cast<float>(std::exp2(logValue(rng)));
      const int expected = directByte(v, stops);
      const int got = tonemapByte(v, thresholds);
      ASSERT_LE(std::abs(got - expected), 1) << "value " << v << ", " << stops << " stops";
      exact += got == expected;
      ++total;
    }
    EXPECT_GE(exact, total - total / 1000) << stops << " stops";
  }
  const auto t = tonemapThresholds(0.0);
  EXPECT_EQ(tonemapByte(0.0f, t), 0);
  EXPECT_EQ(tonemapByte(-1.0f, t), 0);
  EXPECT_EQ(tonemapByte(NAN, t), 0);
  EXPECT_EQ(tonemapByte(INFINITY, t), 255);
}

TEST(Tonemap, HighlightsRollOffUntilTheWhitePoint) {
  EXPECT_DOUBLE_EQ(toneCurve(kToneWhite), 1.0);
  EXPECT_DOUBLE_EQ(toneCurve(4.0 * kToneWhite), 1.0);
  EXPECT_NEAR(toneCurve(1e-3), 1e-3, 2e-6);  // near the identity in the shadows
  const auto t = tonemapThresholds(0.0);
  // Values that plain clamping would all show as 255 stay apart.
  int previous = tonemapByte(0.5f, t);
  for (const float v : {1.0f, 2.0f, 4.0f, 6.0f}) {
    const int b = tonemapByte(v, t);
    EXPECT_GT(b, previous) << v;
    EXPECT_LT(b, 255) << v;
    previous = b;
  }
  EXPECT_EQ(tonemapByte(static_cast<float>(kToneWhite) * 1.001f, t), 255);
  // Exposure is a gain: one stop up shows half the value the same.
  EXPECT_EQ(tonemapByte(0.09f, tonemapThresholds(1.0)), tonemapByte(0.18f, t));
}

TEST(Tonemap, RgbaIsEachChannelAndOpaqueAlpha) {
  io::RgbImage image = io::makeImage(2, 1);
  image.rgb = {0.1f, 0.5f, 2.0f, 0.0f, 9.0f, 0.02f};
  const auto rgba = tonemapRgba8(image, 0.0);
  const auto t = tonemapThresholds(0.0);
  ASSERT_EQ(rgba.size(), 8u);
  for (std::size_t p = 0; p < 2; ++p) {
    for (std::size_t c = 0; c < 3; ++c) EXPECT_EQ(rgba[4 * p + c], tonemapByte(image.rgb[3 * p + c], t));
    EXPECT_EQ(rgba[4 * p + 3], 255);
  }
}

TEST(AutoExposure, LogAverageOverTheMaskedLitPixels) {
  io::RgbImage image = io::makeImage(4, 1);
  // Grey pixels: luminance equals the value (the Rec. 709 weights sum to 1).
  const float grey[] = {0.02f, 0.5f, 0.0f, 100.0f};
  for (int x = 0; x < 4; ++x)
    for (int c = 0; c < 3; ++c) image.at(0, x, c) = grey[x];
  // Black pixels carry no exposure information and are left out.
  EXPECT_NEAR(logAverageLuminance(image, {1, 1, 1, 0}), std::sqrt(0.02 * 0.5), 1e-6);
  EXPECT_NEAR(logAverageLuminance(image), std::cbrt(0.02 * 0.5 * 100.0), 1e-5);
  EXPECT_EQ(logAverageLuminance(image, {0, 0, 1, 0}), 0.0);
  EXPECT_NEAR(keyExposure(0.045), 2.0, 1e-12);  // 0.045 · 2² = 0.18
  EXPECT_EQ(keyExposure(0.0), 0.0);
  EXPECT_EQ(keyExposure(1e-30), kMaxExposureStops);
}

TEST(AutoExposure, FixedAutoAndEasedFromThePreviousFrame) {
  ExposureControl fixed;
  fixed.automatic = false;
  fixed.stops = -1.25;
  EXPECT_EQ(applyExposure(fixed, 0.045), -1.25);
  ExposureControl automatic;
  EXPECT_NEAR(applyExposure(automatic, 0.045), 2.0, 1e-12);
  EXPECT_EQ(applyExposure(automatic, 0.0), 0.0);
  automatic.previousStops = 4.0;
  automatic.adaptation = 0.25;
  EXPECT_NEAR(applyExposure(automatic, 0.045), 3.5, 1e-12);  // a quarter of the way from 4 to 2
  EXPECT_EQ(applyExposure(automatic, 0.0), 4.0);             // nothing lit: keep the previous
  EXPECT_NEAR(exposureAdaptation(kExposureTimeConstant), 1.0 - std::exp(-1.0), 1e-12);
  EXPECT_EQ(exposureAdaptation(0.0), 0.0);
  EXPECT_GT(exposureAdaptation(10.0), 0.999);
}

}  // namespace
}  // namespace haarcast::render
