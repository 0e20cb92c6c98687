// Auto exposure on the CPU: the frame metered by the rule of
// core/shared_exposure.h (the whole frame, objects weighted, a highlight
// guard) in the very steps exposure.comp takes on the device, so both
// backends count the same histograms and choose the same exposure.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "haarcast/core/shared_layout.h"
#include "haarcast/io/image.h"
#include "haarcast/render/tonemap.h"

namespace haarcast::render {

// Weighted counts per bin (shared::meterBin) of the pixels with luminance
// Y > 0: of Y, and of the brightest channel.
struct ExposureHistograms {
  std::array<std::uint32_t, shared::kMeterBins> luminance{};
  std::array<std::uint32_t, shared::kMeterBins> peak{};
};

// objectMask[p] ≠ 0 marks an object pixel (weight shared::kMeterObjectWeight);
// the rest, and every pixel when the mask is empty, are backdrop. On up to
// `threads` threads (0 = the hardware's), each counting its own rows: the
// counts are integers, so the sum does not depend on the split.
ExposureHistograms meterHistograms(const io::RgbImage& image, const std::vector<std::uint8_t>& objectMask,
                                   unsigned threads = 1);

// The push block exposure.comp gets for a request: the control, log2 of the
// key and of the curve's highlight (toneHighlight), the stops bound.
shared::ExposurePush exposurePush(const ExposureControl& control, ToneCurve curve);

// What exposure.comp leaves in ExposureResult for these histograms.
shared::ExposureResult meterExposure(const ExposureHistograms& histograms, const shared::ExposurePush& push);

// Both steps for a frame: the exposure its RGBA8 is made with is `stops`.
shared::ExposureResult meterExposure(const io::RgbImage& image, const std::vector<std::uint8_t>& objectMask,
                                     const ExposureControl& control, ToneCurve curve, unsigned threads = 1);

}  // namespace haarcast::render
