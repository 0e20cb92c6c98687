// The display transform: linear radiance → 8-bit sRGB, one definition for
// `render`'s PNGs, the service's frames and the Vulkan tonemap pass.
//
//   x = 2^stops · L                      exposure
//   y = x·(1 + x/W²) / (1 + x)           Reinhard's extended curve (Reinhard et
//                                        al. 2002, eq. 4), white point W: x = W
//                                        shows as 1, so highlights roll off
//                                        instead of clipping at x = 1
//   byte = round(255 · sRGB(min(y, 1)))  IEC 61966-2-1
//
// Auto exposure puts the log-average luminance of the lit object pixels at
// Reinhard's key 0.18 (eq. 1–2 of the same paper), eased from the previous
// frame's exposure so a moving view does not make the image pump.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "haarcast/io/image.h"

namespace haarcast::render {

inline constexpr double kToneWhite = 8.0;       // W: the exposed value shown as white
inline constexpr double kExposureKey = 0.18;    // Reinhard's middle grey
inline constexpr double kMaxExposureStops = 32.0;  // |stops| beyond this is an error (or clamped, for auto)

// The curve on exposed values: 0 → 0, monotone, W → 1, clamped to 1 beyond
// W; NaN and negatives → 0.
double toneCurve(double exposed);

// The 8-bit code of one linear value. The encoding compares against the 255
// code boundaries below (so the Vulkan pass, which counts the same float
// thresholds, gives the same byte for every input).
std::uint8_t tonemapByte(float linear, const std::array<float, 256>& thresholds);

// thresholds[k], k = 1 … 255: the least linear value (before the gain
// 2^stops) whose code is ≥ k, i.e. the inverse of the transform at the
// rounding boundary (k − ½)/255. thresholds[0] = 0 (unused).
std::array<float, 256> tonemapThresholds(double exposureStops);

// RGBA8 (alpha 255), row 0 at the top, 4 bytes per pixel.
std::vector<std::uint8_t> tonemapRgba8(const io::RgbImage& image, double exposureStops);

// The log-average luminance (Rec. 709 weights) of the pixels with mask ≠ 0
// and luminance > 0 (an empty mask means every pixel); 0 when there are none.
double logAverageLuminance(const io::RgbImage& image, const std::vector<std::uint8_t>& mask = {});

// How a frame is exposed.
struct ExposureControl {
  bool automatic = true;
  double stops = 0.0;  // the exposure when not automatic
  // Automatic: the exposure of the previous frame of the same stream, if
  // any, and how far (0 … 1] to move from it towards this frame's target.
  std::optional<double> previousStops;
  double adaptation = 1.0;
};

// The stops that put logAverage at kExposureKey, within ±kMaxExposureStops;
// 0 when logAverage ≤ 0 (nothing lit).
double keyExposure(double logAverage);

// The exposure a frame uses: the fixed stops, or the key exposure of the
// frame's measure eased from the previous frame's (the previous one is kept
// when nothing is lit).
double applyExposure(const ExposureControl& control, double logAverage);

// The easing factor for frames dt seconds apart: 1 − e^(−dt/τ), so the
// exposure settles in a few τ whatever the frame rate.
inline constexpr double kExposureTimeConstant = 0.4;  // τ, seconds
double exposureAdaptation(double dtSeconds);

}  // namespace haarcast::render
