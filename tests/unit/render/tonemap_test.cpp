// The display transform (render/tonemap.h) against its formula evaluated
// directly in double, for each tone curve, and the curves against values
// worked out by hand from their published forms. Auto exposure's metering
// is exposure_meter_test.cpp.
#include "haarcast/render/tonemap.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>
#include <random>

#include <gtest/gtest.h>

namespace haarcast::render {
namespace {

// The formula of tonemap.h written out: gain, the curve, clamp,
// IEC 61966-2-1, rounding.
int directByte(double linear, double stops, ToneCurve curve) {
  const double x = linear * std::exp2(stops);
  if (!(x > 0.0)) return 0;
  const double y = std::clamp(toneCurve(x, curve), 0.0, 1.0);
  const double s = y <= 0.0031308 ? 12.92 * y : 1.055 * std::pow(y, 1.0 / 2.4) - 0.055;
  return static_cast<int>(std::lround(s * 255.0));
}

class TonemapCurve : public ::testing::TestWithParam<ToneCurve> {};

TEST_P(TonemapCurve, BytesAreTheFormulaExceptAtFloatRoundingOfACodeBoundary) {
  const ToneCurve curve = GetParam();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> logValue(-16.0, 6.0);
  for (const double stops : {-3.0, 0.0, 1.5}) {
    const auto thresholds = tonemapThresholds(stops, curve);
    int exact = 0, total = 0;
    for (int i = 0; i < 20000; ++i) {
      const float v = static_cast<float>(std::exp2(logValue(rng)));
      const int expected = directByte(v, stops, curve);
      const int got = tonemapByte(v, thresholds);
      ASSERT_LE(std::abs(got - expected), 1) << "value " << v << ", " << stops << " stops";
      exact += got == expected;
      ++total;
    }
    EXPECT_GE(exact, total - total / 1000) << stops << " stops";
  }
  const auto t = tonemapThresholds(0.0, curve);
  EXPECT_EQ(tonemapByte(0.0f, t), 0);
  EXPECT_EQ(tonemapByte(-1.0f, t), 0);
  EXPECT_EQ(tonemapByte(NAN, t), 0);
  EXPECT_EQ(tonemapByte(INFINITY, t), 255);
  // Every code is reached, in order: the curve never falls.
  for (int k = 2; k < 256; ++k) EXPECT_LT(t[static_cast<std::size_t>(k - 1)], t[static_cast<std::size_t>(k)]) << k;
  // The highlight guard's value shows as kHighlightCode, a hair more as the next.
  const double h = toneHighlight(curve);
  EXPECT_EQ(tonemapByte(static_cast<float>(h * 0.999), t), kHighlightCode);
  EXPECT_EQ(tonemapByte(static_cast<float>(h * 1.001), t), kHighlightCode + 1);
}

TEST_P(TonemapCurve, NeverFallsAndStaysWithinZeroToOne) {
  const ToneCurve curve = GetParam();
  double previous = 0.0;
  for (double lx = -20.0; lx <= 10.0; lx += 1.0 / 64.0) {
    const double y = toneCurve(std::exp2(lx), curve);
    ASSERT_GE(y, previous) << toneCurveName(curve) << " at 2^" << lx;
    ASSERT_LE(y, 1.0);
    previous = y;
  }
  EXPECT_EQ(toneCurve(0.0, curve), 0.0);
  EXPECT_EQ(toneCurve(-1.0, curve), 0.0);
  EXPECT_EQ(toneCurve(NAN, curve), 0.0);
  EXPECT_EQ(parseToneCurve(toneCurveName(curve)), curve);
}

INSTANTIATE_TEST_SUITE_P(Curves, TonemapCurve, ::testing::ValuesIn(kToneCurves),
                         [](const auto& p) { return std::string(toneCurveName(p.param)); });

// The curves at points worked out from their published forms.
TEST(Tonemap, CurvesAtHandComputedPoints) {
  // Reinhard's extended curve, W = 8: 0.18·(1 + 0.18/64)/1.18; 1·(1 + 1/64)/2.
  EXPECT_NEAR(toneCurve(0.18, ToneCurve::Reinhard), 0.18 * (1.0 + 0.18 / 64.0) / 1.18, 1e-15);
  EXPECT_NEAR(toneCurve(1.0, ToneCurve::Reinhard), 65.0 / 128.0, 1e-15);
  // Narkowicz: x = 1 gives (2.51 + 0.03)/(2.43 + 0.59 + 0.14) = 127/158; it
  // reaches 1 where 0.08x² − 0.56x − 0.14 = 0 (x ≈ 7.24) and stays there.
  EXPECT_NEAR(toneCurve(1.0, ToneCurve::Aces), 127.0 / 158.0, 1e-15);
  EXPECT_NEAR(toneCurve(0.18, ToneCurve::Aces), 0.2668989203894968, 1e-15);
  const double acesWhite = (0.56 + std::sqrt(0.56 * 0.56 + 4.0 * 0.08 * 0.14)) / 0.16;  // ≈ 7.24
  EXPECT_NEAR(toneCurve(acesWhite * 0.999, ToneCurve::Aces), 1.0, 1e-4);
  EXPECT_LT(toneCurve(acesWhite * 0.999, ToneCurve::Aces), 1.0);
  EXPECT_EQ(toneCurve(acesWhite * 1.001, ToneCurve::Aces), 1.0);
  // AgX: middle grey sits 10/16.5 along the log window, where Wrensch's
  // polynomial is 0.49673…; raised to 2.2. The window's top, 2^4.026069
  // (0.18·2^6.5 as the fit rounds it), and all above it show p(1)^2.2 =
  // 0.99858^2.2; its bottom and below, 0.
  EXPECT_NEAR(toneCurve(0.18, ToneCurve::Agx), 0.2145190198456818, 1e-6);
  EXPECT_NEAR(toneCurve(1.0, ToneCurve::Agx), 0.5901591271831184, 1e-6);
  EXPECT_NEAR(toneCurve(std::exp2(4.026069), ToneCurve::Agx), std::pow(0.99858, 2.2), 1e-12);
  EXPECT_NEAR(toneCurve(1e3, ToneCurve::Agx), std::pow(0.99858, 2.2), 1e-12);
  EXPECT_EQ(toneCurve(0.18 * std::exp2(-10.5), ToneCurve::Agx), 0.0);
  EXPECT_EQ(toneCurveNames(), "reinhard, aces, agx");
  EXPECT_FALSE(parseToneCurve("filmic"));
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

// The image's bytes keep a channel's last code where the next value is in
// its bracket: still each value's own search, along runs of equal values,
// slow ramps, steps, the bracket's very edges, values past the white, zero,
// negative, infinite and NaN ones, for each curve.
TEST(Tonemap, RgbaKeepsEachValuesOwnCodeAlongRunsRampsAndSteps) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (const ToneCurve curve : kToneCurves) {
    const ToneThresholds t = tonemapThresholds(-0.5, curve);
    std::vector<float> values;
    for (int run = 0; run < 400; ++run) {
      const float v = 4.0f * u(rng) * u(rng);
      switch (run % 5) {
        case 0: values.insert(values.end(), 7, v); break;                                 // a run
        case 1: for (int k = 0; k < 9; ++k) values.push_back(v * (1.0f + 0.002f * k)); break;  // a ramp
        case 2: {  // each side of a code's boundary
          const float edge = t[1 + rng() % (shared::kToneCodes - 1)];
          if (std::isfinite(edge)) values.insert(values.end(), {edge, std::nextafter(edge, 0.0f), edge, std::nextafter(edge, 1e30f)});
          break;
        }
        case 3: values.insert(values.end(), {0.0f, -1.0f, 50.0f, std::numeric_limits<float>::infinity(), v}); break;
        default: values.insert(values.end(), {std::numeric_limits<float>::quiet_NaN(), v, std::numeric_limits<float>::quiet_NaN()}); break;
      }
    }
    // Each value a pixel's red, its green the previous value's, its blue
    // a constant: every channel sees the sequence's neighbours in turn.
    io::RgbImage image = io::makeImage(static_cast<int>(values.size()), 1);
    for (std::size_t p = 0; p < values.size(); ++p) {
      image.rgb[3 * p] = values[p];
      image.rgb[3 * p + 1] = values[p > 0 ? p - 1 : 0];
      image.rgb[3 * p + 2] = 0.25f;
    }
    const auto rgba = tonemapRgba8(image, -0.5, curve);
    for (std::size_t i = 0; i < image.rgb.size(); ++i)
      ASSERT_EQ(rgba[4 * (i / 3) + i % 3], tonemapByte(image.rgb[i], t)) << "value " << image.rgb[i] << " at " << i;
  }
}

}  // namespace
}  // namespace haarcast::render
