#include "haarcast/render/tonemap.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "haarcast/core/parallel.h"

namespace haarcast::render {

namespace {

// Narkowicz's ACES fit: x(ax + b) / (x(cx + d) + e).
constexpr double kAcesA = 2.51, kAcesB = 0.03, kAcesC = 2.43, kAcesD = 0.59, kAcesE = 0.14;
// AgX's log2 window: middle grey 0.18 with 10 stops below and 6.5 above.
constexpr double kAgxMinEv = -12.47393, kAgxMaxEv = 4.026069;
constexpr double kAgxDisplayGamma = 2.2;

// Wrensch's polynomial fit of the AgX base contrast sigmoid on t ∈ [0, 1]
// (mean squared error 3.7e-6); it rises on all of [0, 1] (the tests check),
// from −0.00232 to 0.99858.
double agxSigmoid(double t) {
  const double t2 = t * t, t4 = t2 * t2;
  return 15.5 * t4 * t2 - 40.14 * t4 * t + 31.96 * t4 - 6.868 * t2 * t + 0.4298 * t2 + 0.1191 * t - 0.00232;
}

// The least x with toneCurve(x) ≥ y, for y in (0, 1]; +∞ when the curve
// never reaches y.
double inverseToneCurve(double y, ToneCurve curve) {
  switch (curve) {
    case ToneCurve::Reinhard: {
      // The positive root of x²/W² + (1 − y)·x − y = 0, written without the
      // cancellation of the textbook form at small y.
      const double b = 1.0 - y;
      return 2.0 * y / (b + std::sqrt(b * b + 4.0 * y / (kToneWhite * kToneWhite)));
    }
    case ToneCurve::Aces: {
      // (a − cy)·x² + (b − dy)·x − ey = 0 with a − cy > 0 for y ≤ 1: the
      // positive root, in whichever form does not cancel.
      const double qa = kAcesA - kAcesC * y, qb = kAcesB - kAcesD * y, qc = kAcesE * y;
      const double root = std::sqrt(qb * qb + 4.0 * qa * qc);
      return qb < 0.0 ? (root - qb) / (2.0 * qa) : 2.0 * qc / (qb + root);
    }
    case ToneCurve::Agx: {
      const double s = std::pow(y, 1.0 / kAgxDisplayGamma);
      if (s > agxSigmoid(1.0)) return std::numeric_limits<double>::infinity();
      double lo = 0.0, hi = 1.0;  // the sigmoid rises: bisect for the least t with p(t) ≥ s
      for (int i = 0; i < 64; ++i) {
        const double mid = 0.5 * (lo + hi);
        (agxSigmoid(mid) >= s ? hi : lo) = mid;
      }
      return std::exp2(kAgxMinEv + hi * (kAgxMaxEv - kAgxMinEv));
    }
  }
  return 0.0;
}

double srgbToLinear(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }

}  // namespace

std::string_view toneCurveName(ToneCurve curve) {
  switch (curve) {
    case ToneCurve::Reinhard: return "reinhard";
    case ToneCurve::Aces: return "aces";
    case ToneCurve::Agx: return "agx";
  }
  return "?";
}

std::optional<ToneCurve> parseToneCurve(std::string_view name) {
  for (const ToneCurve c : kToneCurves)
    if (toneCurveName(c) == name) return c;
  return std::nullopt;
}

std::string toneCurveNames() {
  std::string out;
  for (const ToneCurve c : kToneCurves) out += (out.empty() ? "" : ", ") + std::string(toneCurveName(c));
  return out;
}

double toneCurve(double x, ToneCurve curve) {
  if (!(x > 0.0)) return 0.0;  // also NaN
  switch (curve) {
    case ToneCurve::Reinhard:
      if (x >= kToneWhite) return 1.0;
      return x * (1.0 + x / (kToneWhite * kToneWhite)) / (1.0 + x);
    case ToneCurve::Aces:
      return std::min(1.0, x * (kAcesA * x + kAcesB) / (x * (kAcesC * x + kAcesD) + kAcesE));
    case ToneCurve::Agx: {
      const double t = std::clamp((std::log2(x) - kAgxMinEv) / (kAgxMaxEv - kAgxMinEv), 0.0, 1.0);
      return std::pow(std::clamp(agxSigmoid(t), 0.0, 1.0), kAgxDisplayGamma);
    }
  }
  return 0.0;
}

ToneThresholds tonemapThresholds(double exposureStops, ToneCurve curve) {
  const double gain = std::exp2(exposureStops);
  ToneThresholds t{};
  for (std::size_t k = 1; k < t.size(); ++k) {
    const double y = srgbToLinear((static_cast<double>(k) - 0.5) / (shared::kToneCodes - 1));
    t[k] = static_cast<float>(inverseToneCurve(y, curve) / gain);
  }
  return t;
}

double toneHighlight(ToneCurve curve) { return inverseToneCurve(srgbToLinear((kHighlightCode + 0.5) / 255.0), curve); }

std::uint8_t tonemapByte(float value, const ToneThresholds& threshold) {
  return static_cast<std::uint8_t>(shared::tonemapCode(value, threshold));
}

std::vector<std::uint8_t> tonemapRgba8(const io::RgbImage& image, double exposureStops, ToneCurve curve,
                                       unsigned threads) {
  const ToneThresholds thresholds = tonemapThresholds(exposureStops, curve);
  const std::size_t pixels = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
  std::vector<std::uint8_t> out(pixels * 4);
  constexpr std::size_t kBand = std::size_t{1} << 16;  // pixels a task
  parallelFor((pixels + kBand - 1) / kBand, [&](std::size_t b) {
    // Each channel's last code, kept where the next value lies in its
    // bracket (most neighbours do): the code is the one k with
    // threshold[k] ≤ value < threshold[k + 1] (k = 0: below threshold[1];
    // NaN takes 0 as the search gives it), so the bytes are the search's.
    std::array<std::uint32_t, 3> last{0u, 0u, 0u};
    for (std::size_t p = b * kBand; p < std::min(pixels, (b + 1) * kBand); ++p) {
      for (std::size_t c = 0; c < 3; ++c) {
        const float value = image.rgb[3 * p + c];
        const std::uint32_t k = last[c];
        const bool inBracket = (k == 0u || value >= thresholds[k]) && (k + 1u == shared::kToneCodes || !(value >= thresholds[k + 1u]));
        if (!inBracket) last[c] = shared::tonemapCode(value, thresholds);
        out[4 * p + c] = static_cast<std::uint8_t>(last[c]);
      }
      out[4 * p + 3] = 255;
    }
  }, {}, threads);
  return out;
}

double exposureAdaptation(double dtSeconds) {
  if (!(dtSeconds > 0.0)) return 0.0;
  return 1.0 - std::exp(-dtSeconds / kExposureTimeConstant);
}

}  // namespace haarcast::render
