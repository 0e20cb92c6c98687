#include "haarcast/render/exposure_meter.h"

#include <cmath>

namespace haarcast::render {

ExposureHistograms meterHistograms(const io::RgbImage& image, const std::vector<std::uint8_t>& objectMask) {
  ExposureHistograms h;
  const std::size_t pixels = image.rgb.size() / 3;
  for (std::size_t p = 0; p < pixels; ++p) {
    const glm::vec3 c(image.rgb[3 * p], image.rgb[3 * p + 1], image.rgb[3 * p + 2]);
    const float y = shared::meterLuminance(c);
    const std::uint32_t w = shared::meterWeight(y, p < objectMask.size() && objectMask[p] != 0);
    if (w == 0) continue;
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
  return shared::meterReadout(h, push);
}

shared::ExposureResult meterExposure(const io::RgbImage& image, const std::vector<std::uint8_t>& objectMask,
                                     const ExposureControl& control, ToneCurve curve) {
  return meterExposure(meterHistograms(image, objectMask), exposurePush(control, curve));
}

}  // namespace haarcast::render
