#include "haarcast/render/exposure_meter.h"

#include <cmath>

namespace haarcast::render {

using shared::kMeterBins;

ExposureHistograms meterHistograms(const io::RgbImage& image, const std::vector<std::uint8_t>& objectMask) {
  ExposureHistograms h;
  const std::size_t pixels = image.rgb.size() / 3;
  for (std::size_t p = 0; p < pixels; ++p) {
    const glm::vec3 c(image.rgb[3 * p], image.rgb[3 * p + 1], image.rgb[3 * p + 2]);
    const float y = shared::meterLuminance(c);
    // Black pixels (shadowed, or a black backdrop) carry no exposure
    // information; neither do NaN and ∞.
    if (!(y > 0.0f) || std::isinf(y)) continue;
    const bool object = p < objectMask.size() && objectMask[p] != 0;
    const std::uint32_t w = object ? shared::kMeterObjectWeight : shared::kMeterBackdropWeight;
    h.luminance[shared::meterBin(y)] += w;
    h.peak[shared::meterBin(shared::meterPeak(c))] += w;
  }
  return h;
}

shared::ExposurePush exposurePush(const ExposureControl& control, ToneCurve curve) {
  shared::ExposurePush p{};
  p.automatic = control.automatic ? 1u : 0u;
  p.hasPrevious = control.previousStops ? 1u : 0u;
  p.previousStops = static_cast<float>(control.previousStops.value_or(0.0));
  p.adaptation = static_cast<float>(control.adaptation);
  p.fixedStops = static_cast<float>(control.stops);
  p.keyLog2 = static_cast<float>(std::log2(kExposureKey));
  p.highlightLog2 = static_cast<float>(std::log2(toneHighlight(curve)));
  p.maxStops = static_cast<float>(kMaxExposureStops);
  return p;
}

shared::ExposureResult meterExposure(const ExposureHistograms& h, const shared::ExposurePush& push) {
  // exposure.comp's last step, line for line, in float.
  shared::ExposureResult r{};
  std::uint32_t total = 0;
  float sumLog2 = 0.0f;
  for (std::uint32_t b = 0; b < kMeterBins; ++b) {
    total += h.luminance[b];
    sumLog2 += static_cast<float>(h.luminance[b]) * shared::meterBinLog2(b);
  }
  float target = 0.0f;
  if (total != 0) {
    r.meanLog2 = sumLog2 / static_cast<float>(total);
    const std::uint32_t need = shared::meterHighlightWeight(total);
    std::uint32_t above = 0, bin = kMeterBins - 1;
    for (; bin > 0; --bin) {
      above += h.peak[bin];
      if (above >= need) break;
    }
    r.highlightLog2 = shared::meterBinLog2(bin);
    r.logAverage = std::exp2(r.meanLog2);
    target = shared::meteredStops(r.meanLog2, r.highlightLog2, push);
  }
  r.weight = total;
  r.stops = shared::exposureStops(total, target, push);
  r.gain = push.automatic != 0u ? std::exp2(r.stops) : 1.0f;
  return r;
}

shared::ExposureResult meterExposure(const io::RgbImage& image, const std::vector<std::uint8_t>& objectMask,
                                     const ExposureControl& control, ToneCurve curve) {
  return meterExposure(meterHistograms(image, objectMask), exposurePush(control, curve));
}

}  // namespace haarcast::render
