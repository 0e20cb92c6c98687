// Auto exposure's metering (core/shared_exposure.h, render/exposure_meter.h)
// against values worked out by hand: the bins, the weighted log-average,
// the highlight guard and its cap, the easing. The device's copy of the
// same steps is checked against this one in tests/unit/gpu/exposure_pass_test.cpp.
#include "haarcast/render/exposure_meter.h"
#include "haarcast/render/tonemap.h"

#include <cmath>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

namespace haarcast::render {
namespace {

// A grey pixel 2^e·(1 + 1/32) sits at the centre of bin k = 0 of its
// octave, so its bin stands for exactly e + log2(1 + 1/32).
constexpr double kCentre = 1.0 + 1.0 / 32.0;
const double kCentreLog2 = std::log2(kCentre);

float grey(int e) { return static_cast<float>(std::ldexp(kCentre, e)); }

io::RgbImage greys(const std::vector<float>& values) {
  io::RgbImage image = io::makeImage(static_cast<int>(values.size()), 1);
  for (std::size_t x = 0; x < values.size(); ++x)
    for (int c = 0; c < 3; ++c) image.at(0, static_cast<int>(x), c) = values[x];
  return image;
}

TEST(ExposureMeter, BinsAreSixteenthsOfAnOctaveReadOffTheBits) {
  EXPECT_EQ(shared::meterBin(1.0f), 32u * 16u);             // 2^0: octave 32 of the 64 from 2^−32
  EXPECT_EQ(shared::meterBin(1.0625f), 32u * 16u + 1u);     // the next sixteenth
  EXPECT_EQ(shared::meterBin(0.5f), 31u * 16u);
  EXPECT_EQ(shared::meterBin(1e-30f), 0u);                  // below 2^−32: the first bin
  EXPECT_EQ(shared::meterBin(1e30f), shared::kMeterBins - 1u);  // above 2^32: the last
  for (const int e : {-20, -1, 0, 3, 17}) {
    EXPECT_NEAR(shared::meterBinLog2(shared::meterBin(grey(e))), e + kCentreLog2, 1e-6) << e;
  }
  // Every bin's centre, from its value: within float rounding.
  for (std::uint32_t b = 0; b < shared::kMeterBins; b += 37) {
    const double lo = std::ldexp(1.0 + (b & 15u) / 16.0, static_cast<int>(b >> 4) - 32);
    const double hi = std::ldexp(1.0 + ((b & 15u) + 1) / 16.0, static_cast<int>(b >> 4) - 32);
    EXPECT_NEAR(shared::meterBinLog2(b), std::log2(0.5 * (lo + hi)), 2e-6) << b;
  }
}

TEST(ExposureMeter, HistogramsWeighObjectsFourTimesAndSkipWhatCarriesNoLight) {
  io::RgbImage image = greys({grey(-4), grey(2), 0.0f, NAN, INFINITY, grey(2)});
  image.at(0, 5, 0) = 8.0f;  // reddish: its brightest channel is not its luminance
  const std::vector<std::uint8_t> mask = {1, 0, 1, 1, 1, 0};
  const ExposureHistograms h = meterHistograms(image, mask);
  std::uint32_t lum = 0, peak = 0;
  for (std::uint32_t b = 0; b < shared::kMeterBins; ++b) {
    lum += h.luminance[b];
    peak += h.peak[b];
  }
  EXPECT_EQ(lum, 4u + 1u + 1u);  // one object pixel, two backdrop; black, NaN and ∞ left out
  EXPECT_EQ(peak, lum);
  EXPECT_EQ(h.luminance[shared::meterBin(grey(-4))], 4u);
  EXPECT_EQ(h.luminance[shared::meterBin(grey(2))], 1u);
  EXPECT_EQ(h.peak[shared::meterBin(8.0f)], 1u);
}

// One object pixel at 2^−4 and one backdrop pixel at 2^e (both at bin
// centres): the weighted mean log2 is (4·(−4) + e)/5 + log2(1 + 1/32); the
// brightest 1% of the weight is the backdrop pixel.
shared::ExposureResult twoPixels(int e, ToneCurve curve = ToneCurve::Reinhard) {
  return meterExposure(greys({grey(-4), grey(e)}), {1, 0}, ExposureControl{}, curve);
}

// Counted on several threads, band by band, the histograms are the one
// thread's exactly (integer counts); so are the RGBA8 bytes. An image of
// 300 × 500 pixels: three bands of 64K and a part, every bin class (zero,
// negative, NaN, a spread of greys), objects on a pattern.
TEST(ExposureMeter, ThreadsCountAndEncodeWhatOneThreadDoes) {
  io::RgbImage image = io::makeImage(300, 500);
  std::vector<std::uint8_t> mask(300 * 500);
  for (int y = 0; y < 500; ++y) {
    for (int x = 0; x < 300; ++x) {
      const int i = y * 300 + x;
      for (int c = 0; c < 3; ++c) image.at(y, x, c) = static_cast<float>(std::ldexp(1.0 + (i * 7 + c) % 97 / 97.0, (i % 41) - 20));
      if (i % 13 == 0) image.at(y, x, 0) = 0.0f;
      if (i % 17 == 0) image.at(y, x, 1) = -1.0f;
      if (i % 19 == 0) image.at(y, x, 2) = std::nanf("");
      mask[static_cast<std::size_t>(i)] = (x / 7 + y / 5) % 3 == 0;
    }
  }
  const ExposureHistograms one = meterHistograms(image, mask, 1);
  for (const unsigned threads : {2u, 3u, 0u}) {
    const ExposureHistograms many = meterHistograms(image, mask, threads);
    EXPECT_EQ(many.luminance, one.luminance) << threads << " threads";
    EXPECT_EQ(many.peak, one.peak) << threads << " threads";
    EXPECT_EQ(tonemapRgba8(image, 1.5, ToneCurve::Reinhard, threads), tonemapRgba8(image, 1.5, ToneCurve::Reinhard, 1));
  }
  std::uint64_t weight = 0;
  for (const std::uint32_t w : one.luminance) weight += w;
  EXPECT_GT(weight, 100000u);  // most pixels carry light and are counted
}

TEST(ExposureMeter, KeyExposureOfTheWeightedLogAverage) {
  const shared::ExposureResult r = twoPixels(2);
  const double mean = (4.0 * -4.0 + 2.0) / 5.0 + kCentreLog2;
  EXPECT_NEAR(r.meanLog2, mean, 1e-6);
  EXPECT_NEAR(r.logAverage, std::exp2(mean), 1e-6);
  EXPECT_NEAR(r.highlightLog2, 2.0 + kCentreLog2, 1e-6);
  EXPECT_EQ(r.weight, 5u);
  // The backdrop at 2^2 exposed by the key stays under the highlight: the key stands.
  const double key = std::log2(kExposureKey) - mean;
  ASSERT_LT(2.0 + kCentreLog2 + key, std::log2(toneHighlight(ToneCurve::Reinhard)));
  EXPECT_NEAR(r.stops, key, 1e-5);
  EXPECT_NEAR(r.gain, std::exp2(key), 1e-5);
}

TEST(ExposureMeter, TheHighlightGuardHoldsABrightBackdropBelowWhite) {
  for (const ToneCurve curve : kToneCurves) {
    const shared::ExposureResult r = twoPixels(5, curve);
    const double key = std::log2(kExposureKey) - ((4.0 * -4.0 + 5.0) / 5.0 + kCentreLog2);
    const double guard = std::log2(toneHighlight(curve)) - (5.0 + kCentreLog2);
    ASSERT_LT(guard, key) << toneCurveName(curve);
    ASSERT_GT(guard, key - shared::kMeterMaxHighlightPull) << toneCurveName(curve);
    EXPECT_NEAR(r.stops, guard, 1e-5) << toneCurveName(curve);
    // So the backdrop shows short of white, at the highlight code.
    const auto t = tonemapThresholds(r.stops, curve);
    EXPECT_EQ(tonemapByte(0.999f * grey(5), t), kHighlightCode) << toneCurveName(curve);
  }
}

TEST(ExposureMeter, TheGuardTakesAtMostItsCapOffTheKey) {
  const shared::ExposureResult r = twoPixels(9);  // a sun in view
  const double key = std::log2(kExposureKey) - ((4.0 * -4.0 + 9.0) / 5.0 + kCentreLog2);
  EXPECT_NEAR(r.stops, key - shared::kMeterMaxHighlightPull, 1e-5);
}

TEST(ExposureMeter, TheHighlightIsTheBrightestHundredthOfTheWeight) {
  // 99 object pixels at 2^−2 (weight 396) and 4 backdrop pixels at 2^3:
  // the brightest 4 of 400 are exactly the top 1%, so they set the guard;
  // with 3 of them the top 1% reaches down into the objects.
  std::vector<float> values(99, grey(-2));
  std::vector<std::uint8_t> mask(99, 1);
  for (int i = 0; i < 4; ++i) {
    values.push_back(grey(3));
    mask.push_back(0);
  }
  EXPECT_NEAR(meterExposure(greys(values), mask, {}, ToneCurve::Reinhard).highlightLog2, 3.0 + kCentreLog2, 1e-6);
  values.pop_back();
  mask.pop_back();
  EXPECT_NEAR(meterExposure(greys(values), mask, {}, ToneCurve::Reinhard).highlightLog2, -2.0 + kCentreLog2, 1e-6);
}

TEST(ExposureMeter, FixedAutoAndEasedFromThePreviousFrame) {
  const io::RgbImage image = greys({grey(-4), grey(2)});
  const std::vector<std::uint8_t> mask = {1, 0};
  ExposureControl fixed;
  fixed.automatic = false;
  fixed.stops = -1.25;
  const shared::ExposureResult f = meterExposure(image, mask, fixed, ToneCurve::Reinhard);
  EXPECT_EQ(f.stops, -1.25f);
  EXPECT_EQ(f.gain, 1.0f);  // a fixed exposure lives in the thresholds
  ExposureControl automatic;
  const double target = meterExposure(image, mask, automatic, ToneCurve::Reinhard).stops;
  automatic.previousStops = target + 2.0;
  automatic.adaptation = 0.25;
  EXPECT_NEAR(meterExposure(image, mask, automatic, ToneCurve::Reinhard).stops, target + 1.5, 1e-5);  // a quarter of the way
  const io::RgbImage black = greys({0.0f, 0.0f});
  EXPECT_EQ(meterExposure(black, mask, automatic, ToneCurve::Reinhard).stops, static_cast<float>(target + 2.0));  // nothing lit: kept
  EXPECT_EQ(meterExposure(black, mask, ExposureControl{}, ToneCurve::Reinhard).stops, 0.0f);
  EXPECT_EQ(meterExposure(black, mask, ExposureControl{}, ToneCurve::Reinhard).weight, 0u);
  EXPECT_NEAR(exposureAdaptation(kExposureTimeConstant), 1.0 - std::exp(-1.0), 1e-12);
  EXPECT_EQ(exposureAdaptation(0.0), 0.0);
  EXPECT_GT(exposureAdaptation(10.0), 0.999);
}

}  // namespace
}  // namespace haarcast::render
