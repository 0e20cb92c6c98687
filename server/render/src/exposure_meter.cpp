#include "haarcast/render/exposure_meter.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "haarcast/core/parallel.h"

namespace haarcast::render {

ExposureHistograms meterHistograms(const io::RgbImage& image, const std::vector<std::uint8_t>& objectMask,
                                   unsigned threads) {
  const std::size_t pixels = image.rgb.size() / 3;
  // Bands of 64K pixels, each counted into its own histograms, added after.
  constexpr std::size_t kBand = std::size_t{1} << 16;
  const std::size_t bands = (pixels + kBand - 1) / kBand;
  std::vector<ExposureHistograms> counted(bands);
  parallelFor(bands, [&](std::size_t b) {
    ExposureHistograms& h = counted[b];
    for (std::size_t p = b * kBand; p < std::min(pixels, (b + 1) * kBand); ++p) {
      const glm::vec3 c(image.rgb[3 * p], image.rgb[3 * p + 1], image.rgb[3 * p + 2]);
      const float y = shared::meterLuminance(c);
      const std::uint32_t w = shared::meterWeight(y, p < objectMask.size() && objectMask[p] != 0);
      if (w == 0) continue;
      h.luminance[shared::meterBin(y)] += w;
      h.peak[shared::meterBin(shared::meterPeak(c))] += w;
    }
  }, {}, threads);
  ExposureHistograms h;
  for (const ExposureHistograms& band : counted) {
    for (std::size_t k = 0; k < h.luminance.size(); ++k) {
      h.luminance[k] += band.luminance[k];
      h.peak[k] += band.peak[k];
    }
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
                                     const ExposureControl& control, ToneCurve curve, unsigned threads) {
  return meterExposure(meterHistograms(image, objectMask, threads), exposurePush(control, curve));
}

}  // namespace haarcast::render
