// truth_metrics against sums worked by hand: relative L2, brightness, the
// shadowed/lit split (fractions, error shares) and the shadow threshold.
#include "truth_metrics.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

namespace haarcast::app {
namespace {

std::vector<float> grey(std::initializer_list<float> v) {
  std::vector<float> out;
  for (float x : v) out.insert(out.end(), {x, x, x});
  return out;
}

TEST(TruthMetrics, WholeAndSplitByHand) {
  // Pixels: truth 1, 2, 4, (9 outside the mask); render 1, 1, 5, (0).
  const std::vector<float> truth = grey({1, 2, 4, 9}), test = grey({1, 1, 5, 0});
  const std::vector<std::uint8_t> mask = {1, 1, 1, 0}, shadowed = {0, 1, 0, 1};
  const TruthError e = compareWithTruth(truth, test, mask, shadowed);
  // Per channel: errors 0, −1, 1 → Σ(a−r)² = 3·2 = 6, Σr² = 3·21 = 63, Σr = 21, Σa = 21.
  EXPECT_DOUBLE_EQ(e.mse, 6.0 / 9.0);
  EXPECT_DOUBLE_EQ(e.psnr, 10.0 * std::log10(16.0 / (6.0 / 9.0)));  // peak 4 (the masked 9 is not seen)
  EXPECT_DOUBLE_EQ(e.relativeL2, std::sqrt(6.0 / 63.0));
  EXPECT_DOUBLE_EQ(e.brightness, 1.0);
  // Shadowed: pixel 1 only (pixel 3 is outside the mask). Lit: pixels 0 and 2.
  EXPECT_EQ(e.shadowed.pixels, 1u);
  EXPECT_DOUBLE_EQ(e.shadowed.pixelFraction, 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(e.shadowed.errorShare, 0.5);
  EXPECT_DOUBLE_EQ(e.shadowed.relativeL2, std::sqrt(3.0 / 12.0));
  EXPECT_DOUBLE_EQ(e.shadowed.brightness, 0.5);
  EXPECT_EQ(e.lit.pixels, 2u);
  EXPECT_DOUBLE_EQ(e.lit.errorShare, 0.5);
  EXPECT_DOUBLE_EQ(e.lit.relativeL2, std::sqrt(3.0 / 51.0));
  EXPECT_DOUBLE_EQ(e.lit.brightness, 18.0 / 15.0);
  const nlohmann::json j = toJson(e);
  EXPECT_DOUBLE_EQ(j["shadowed"]["error_share"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(j["relative_l2"].get<double>(), e.relativeL2);
  // No split: everything is lit.
  EXPECT_EQ(compareWithTruth(truth, test, mask, {}).lit.pixels, 3u);
}

TEST(TruthMetrics, ShadowedIsTwoPercentDarkerInLuminance) {
  // Luminance weights 0.2126, 0.7152, 0.0722: a drop in green alone counts 72 %.
  const std::vector<float> unoccluded = grey({1, 1, 1, 1, 1});
  std::vector<float> occluded = grey({0.985f, 0.975f, 1.0f, 0.5f, 0.5f});
  occluded[3 * 2 + 1] = 0.97f;  // green −3 %: luminance −2.1 %
  const std::vector<std::uint8_t> mask = {1, 1, 1, 1, 0};
  const std::vector<std::uint8_t> s = shadowedPixels(occluded, unoccluded, mask);
  EXPECT_EQ(s, (std::vector<std::uint8_t>{0, 1, 1, 1, 0}));
  EXPECT_THROW(shadowedPixels(occluded, grey({1}), mask), std::invalid_argument);
  EXPECT_THROW(compareWithTruth(occluded, unoccluded, std::vector<std::uint8_t>(5, 0), {}), std::invalid_argument);
}

TEST(TruthMetrics, DarkPixelsAreMostlyLitInTheTruthAndOverAFifthDarkerInTheRender) {
  // Open light 10 everywhere. Truth: 6 (keeps 60 %), 4 (40 %: not eligible),
  // 8, 9, 5.5 (outside the mask). Render: 4.7 (−21.7 %: dark), 1 (ignored),
  // 6.5 (−18.75 %: not dark), 9.9 (brighter), 0 (outside).
  const std::vector<float> open = grey({10, 10, 10, 10, 10});
  const std::vector<float> truth = grey({6, 4, 8, 9, 5.5f}), test = grey({4.7f, 1, 6.5f, 9.9f, 0});
  const std::vector<std::uint8_t> mask = {1, 1, 1, 1, 0};
  const DarkPixels d = darkPixels(truth, open, test, mask);
  EXPECT_EQ(d.eligible, 3u);
  EXPECT_EQ(d.dark, 1u);
  EXPECT_NEAR(d.worstRatio, 4.7 / 6.0, 1e-6);
  EXPECT_EQ(d.worstPixel, 0u);
  EXPECT_EQ(d.where, (std::vector<std::size_t>{0}));
  // A stricter drop counts pixel 2 too; a stricter share leaves pixel 0 out.
  EXPECT_EQ(darkPixels(truth, open, test, mask, kDarkKeptShare, 0.15).dark, 2u);
  EXPECT_EQ(darkPixels(truth, open, test, mask, 0.65, kDarkDrop).eligible, 2u);
  EXPECT_EQ(toJson(d)["dark"].get<std::size_t>(), 1u);
  EXPECT_THROW(darkPixels(truth, grey({1}), test, mask), std::invalid_argument);
  EXPECT_THROW(darkPixels(truth, open, grey({1}), mask), std::invalid_argument);
}

}  // namespace
}  // namespace haarcast::app
