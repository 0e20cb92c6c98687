#include "haarcast/render/tonemap.h"

#include <algorithm>
#include <cmath>

namespace haarcast::render {

double toneCurve(double x) {
  if (!(x > 0.0)) return 0.0;  // also NaN
  if (x >= kToneWhite) return 1.0;
  return x * (1.0 + x / (kToneWhite * kToneWhite)) / (1.0 + x);
}

namespace {

// x with toneCurve(x) = y, for y in (0, 1]: the positive root of
// x²/W² + (1 − y)·x − y = 0, written without the cancellation of the
// textbook form at small y.
double inverseToneCurve(double y) {
  const double b = 1.0 - y;
  return 2.0 * y / (b + std::sqrt(b * b + 4.0 * y / (kToneWhite * kToneWhite)));
}

double srgbToLinear(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }

}  // namespace

std::array<float, 256> tonemapThresholds(double exposureStops) {
  const double gain = std::exp2(exposureStops);
  std::array<float, 256> t{};
  for (int k = 1; k < 256; ++k) {
    const double y = srgbToLinear((k - 0.5) / 255.0);
    t[static_cast<std::size_t>(k)] = static_cast<float>(inverseToneCurve(y) / gain);
  }
  return t;
}

std::uint8_t tonemapByte(float value, const std::array<float, 256>& threshold) {
  // The largest k with value ≥ threshold[k] (0 when none, and for NaN): the
  // same binary search as shaders/tonemap.comp.
  unsigned code = 0;
  for (unsigned step = 128; step > 0; step >>= 1) {
    const unsigned next = code + step;
    if (next <= 255 && value >= threshold[next]) code = next;
  }
  return static_cast<std::uint8_t>(code);
}

std::vector<std::uint8_t> tonemapRgba8(const io::RgbImage& image, double exposureStops) {
  const std::array<float, 256> thresholds = tonemapThresholds(exposureStops);
  const std::size_t pixels = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
  std::vector<std::uint8_t> out(pixels * 4);
  for (std::size_t p = 0; p < pixels; ++p) {
    for (std::size_t c = 0; c < 3; ++c) out[4 * p + c] = tonemapByte(image.rgb[3 * p + c], thresholds);
    out[4 * p + 3] = 255;
  }
  return out;
}

double logAverageLuminance(const io::RgbImage& image, const std::vector<std::uint8_t>& mask) {
  const std::size_t pixels = image.rgb.size() / 3;
  double sumLog = 0.0;
  std::size_t lit = 0;
  for (std::size_t p = 0; p < pixels; ++p) {
    if (!mask.empty() && (p >= mask.size() || mask[p] == 0)) continue;
    const double y = 0.2126 * image.rgb[3 * p] + 0.7152 * image.rgb[3 * p + 1] + 0.0722 * image.rgb[3 * p + 2];
    // Black pixels (shadowed, or a black backdrop) carry no exposure
    // information and would drag the key towards burning everything else out.
    if (!(y > 0.0) || !std::isfinite(y)) continue;
    sumLog += std::log(y);
    ++lit;
  }
  return lit ? std::exp(sumLog / static_cast<double>(lit)) : 0.0;
}

double keyExposure(double logAverage) {
  if (!(logAverage > 0.0) || !std::isfinite(logAverage)) return 0.0;
  return std::clamp(std::log2(kExposureKey / logAverage), -kMaxExposureStops, kMaxExposureStops);
}

double applyExposure(const ExposureControl& control, double logAverage) {
  if (!control.automatic) return control.stops;
  if (!(logAverage > 0.0)) return control.previousStops.value_or(0.0);
  const double target = keyExposure(logAverage);
  if (!control.previousStops) return target;
  const double a = std::clamp(control.adaptation, 0.0, 1.0);
  return *control.previousStops + a * (target - *control.previousStops);
}

double exposureAdaptation(double dtSeconds) {
  if (!(dtSeconds > 0.0)) return 0.0;
  return 1.0 - std::exp(-dtSeconds / kExposureTimeConstant);
}

}  // namespace haarcast::render
