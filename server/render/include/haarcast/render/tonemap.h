// The display transform: linear radiance → 8-bit sRGB, one definition for
// `render`'s PNGs, the service's frames and the Vulkan tonemap pass.
//
//   x = 2^stops · L                      exposure
//   y = curve(x)                         the tone curve, per channel, one of
//     reinhard  x·(1 + x/W²) / (1 + x)   Reinhard's extended curve (Reinhard et
//                                        al. 2002, eq. 4), white point W: x = W
//                                        shows as 1, so highlights roll off
//                                        instead of clipping at x = 1
//     aces      x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14)
//                                        Narkowicz's fit of the ACES RRT + ODT
//                                        ("ACES Filmic Tone Mapping Curve",
//                                        knarkowicz.wordpress.com, 2016-01-06;
//                                        pre-exposed: 1 shows as ~0.8); 1 at x ≈ 7.24
//     agx       p(t)^2.2, t = (log2 x + 12.47393) / 16.5 clamped to [0, 1]
//                                        the AgX base sigmoid (Sobotka; Blender
//                                        4.0's default view) as Wrensch's 6th-order
//                                        polynomial p ("Minimal AgX
//                                        implementation", iolite-engine.com, 2023;
//                                        the one three.js and Godot use), its
//                                        log2 range 0.18·2^[−10, +6.5]; the 2.2
//                                        power undoes the curve's display
//                                        encoding. Per channel only: AgX's
//                                        inset/outset matrices mix channels and
//                                        are left out (see tonemapThresholds)
//   byte = round(255 · sRGB(clamp(y, 0, 1)))  IEC 61966-2-1
//
// Auto exposure meters the whole frame with the objects weighted (the rule:
// core/shared_exposure.h; render/exposure_meter.h) and eases from the
// previous frame's exposure so a moving view does not make the image pump.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "haarcast/core/shared_tonemap.h"
#include "haarcast/io/image.h"

namespace haarcast::render {

inline constexpr double kToneWhite = 8.0;       // W: the exposed value Reinhard's curve shows as white
inline constexpr double kExposureKey = 0.18;    // Reinhard's middle grey
inline constexpr double kMaxExposureStops = 32.0;  // |stops| beyond this is an error (or clamped, for auto)
// Auto exposure's highlight guard keeps the frame's brightest percent at or
// below this code: short of white, so it does not clip.
inline constexpr int kHighlightCode = 254;

enum class ToneCurve { Reinhard, Aces, Agx };
inline constexpr std::array<ToneCurve, 3> kToneCurves = {ToneCurve::Reinhard, ToneCurve::Aces, ToneCurve::Agx};

// "reinhard" | "aces" | "agx": the name in flags, the protocol's docs and reports.
std::string_view toneCurveName(ToneCurve curve);
std::optional<ToneCurve> parseToneCurve(std::string_view name);
std::string toneCurveNames();  // "reinhard, aces, agx", for error messages

// The curve on exposed values, display-linear: 0 → 0, monotone, clamped to
// [0, 1]; NaN and negatives → 0.
double toneCurve(double exposed, ToneCurve curve = ToneCurve::Reinhard);

// thresholds[k] for the codes k of the display encoding (shared::kToneCodes).
using ToneThresholds = std::array<float, shared::kToneCodes>;

// The 8-bit code of one linear value: shared::tonemapCode, the count of
// code boundaries reached, which the Vulkan pass runs on the same float
// thresholds, so both give the same byte for every input.
std::uint8_t tonemapByte(float linear, const ToneThresholds& thresholds);

// thresholds[k], k = 1 … 255: the least linear value (before the gain
// 2^stops) whose code is ≥ k, i.e. the inverse of the transform at the
// rounding boundary (k − ½)/255 (+∞ for a code the curve never reaches).
// thresholds[0] = 0 (unused). Counting thresholds works for any curve that
// treats each channel alone and never decreases: all three do.
ToneThresholds tonemapThresholds(double exposureStops, ToneCurve curve = ToneCurve::Reinhard);

// RGBA8 (alpha 255), row 0 at the top, 4 bytes per pixel; on up to
// `threads` threads (0 = the hardware's), each pixel alone.
std::vector<std::uint8_t> tonemapRgba8(const io::RgbImage& image, double exposureStops,
                                       ToneCurve curve = ToneCurve::Reinhard, unsigned threads = 1);

// The exposed value the curve shows as kHighlightCode at most: the boundary
// to kHighlightCode + 1 (thresholds[kHighlightCode + 1] at 0 stops).
double toneHighlight(ToneCurve curve);

// How a frame is exposed.
struct ExposureControl {
  bool automatic = true;
  double stops = 0.0;  // the exposure when not automatic
  // Automatic: the exposure of the previous frame of the same stream, if
  // any, and how far (0 … 1] to move from it towards this frame's target.
  std::optional<double> previousStops;
  double adaptation = 1.0;
};

// The easing factor for frames dt seconds apart: 1 − e^(−dt/τ), so the
// exposure settles in a few τ whatever the frame rate.
inline constexpr double kExposureTimeConstant = 0.4;  // τ, seconds
double exposureAdaptation(double dtSeconds);

}  // namespace haarcast::render
