// Auto exposure's metering, shared by the CPU (render/exposure_meter.cpp)
// and the device (shaders/exposure.comp). Part of shared_layout.h, which
// includes it inside its namespace with its macros: include that instead.
//
// The rule (docs/design.md, "Display"): every pixel with luminance Y > 0
// (Rec. 709; NaN and ∞ are left out) counts, an object pixel with weight
// kMeterObjectWeight and a backdrop pixel with kMeterBackdropWeight, so the
// objects set the exposure but a bright sky still has its say.
//   key   = keyLog2 − (weighted mean of log2 Y)          Reinhard's key (0.18)
//   guard = highlightLog2 − log2 P                       P: the weighted
//           percentile of the brightest channel above which lies 1/kMeterHighlightShare
//           of the weight; highlightLog2: the exposed value the tone curve
//           shows as code render::kHighlightCode (254), short of white
//   stops = max(min(key, guard), key − kMeterMaxHighlightPull), within ±maxStops
// So the key exposure stands unless the brightest 1 % would then clip; the
// guard may darken by a few stops at most, so a sun in view does not turn
// the rest to black.
//
// Both measures come from histograms of integer weights over bins read off
// the float's bits (16 per stop, no log or exp per pixel), so the CPU and the
// device count the very same numbers and the measure does not depend on the
// order pixels are added in. A bin stands for the log2 of its centre; the
// weighted mean of those is within 1/32 stop of the true log-average.
#ifndef HAARCAST_CORE_SHARED_EXPOSURE_H
#define HAARCAST_CORE_SHARED_EXPOSURE_H

HC_CONST uint kMeterObjectWeight = 4u;
HC_CONST uint kMeterBackdropWeight = 1u;
HC_CONST uint kMeterHighlightShare = 100u;   // the brightest 1 % of the weight is the highlight
HC_CONST float kMeterMaxHighlightPull = 3.0f;  // stops the guard may take off the key exposure

// A positive float's bits >> kMeterMantissaShift are its biased exponent
// · 16 + its top 4 mantissa bits: bins of 1/16 of an octave. kMeterBins of
// them from 2^−32 (biased exponent 95) to 2^32; values beyond fall in the end bins.
HC_CONST uint kMeterMantissaShift = 19u;
HC_CONST uint kMeterFirstCode = 95u * 16u;
HC_CONST uint kMeterBins = 1024u;

HC_FUNCTION float meterLuminance(vec3 c) {
  HC_PRECISE float y = 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
  return y;
}

HC_FUNCTION float meterPeak(vec3 c) { return max(c.x, max(c.y, c.z)); }

HC_FUNCTION uint meterBin(float value) {
  const uint code = floatBitsToUint(value) >> kMeterMantissaShift;
  return uint(clamp(int(code) - int(kMeterFirstCode), 0, int(kMeterBins) - 1));
}

// log2 of bin b's centre, 2^e·(1 + (k + ½)/16): e plus log2(1 + (k + ½)/16),
// the sixteen values written out (to float precision) so no device log is involved.
HC_FUNCTION float meterBinLog2(uint bin) {
  const uint k = bin & 15u;
  vec4 q = k < 4u    ? vec4(0.0443941206f, 0.129283011f, 0.209453359f, 0.285402209f)
           : k < 8u  ? vec4(0.357551992f, 0.426264763f, 0.491853088f, 0.554588854f)
           : k < 12u ? vec4(0.614709854f, 0.67242533f, 0.727920473f, 0.781359732f)
                     : vec4(0.832890034f, 0.882643044f, 0.930737317f, 0.977279902f);
  return float(int(bin >> 4u) + int(kMeterFirstCode / 16u) - 127) + q[int(k & 3u)];
}

// The least weight that counts as the highlight: ⌈total / kMeterHighlightShare⌉.
HC_FUNCTION uint meterHighlightWeight(uint total) { return (total + kMeterHighlightShare - 1u) / kMeterHighlightShare; }

// Auto exposure on the device (exposure.comp): the push block carries the
// request's render::ExposureControl and what the curve and render/tonemap.h
// fix (render::exposurePush fills it for both backends); the pass leaves its
// measure and choice in ExposureResult, which the tonemap pass reads (x =
// gain · L, gain = 2^stops when automatic, else 1 because the thresholds then
// hold the fixed exposure) and the host reads back.
struct ExposurePush {
  uint automatic;      // 1: the metered exposure, eased from previousStops
  uint hasPrevious;    // 1: previousStops holds the stream's last exposure
  float previousStops;
  float adaptation;    // 0 … 1, the easing towards the target
  float fixedStops;    // the exposure when not automatic
  float keyLog2;       // log2 render::kExposureKey
  float highlightLog2; // log2 of render::toneHighlight(curve)
  float maxStops;      // render::kMaxExposureStops
};

struct ExposureResult {
  float logAverage;     // 2^meanLog2: Frame::logAverageLuminance (0: nothing measured)
  float meanLog2;       // the weighted mean of the luminance bins' log2
  float highlightLog2;  // log2 P, the highlight bin's centre
  float stops;          // the exposure used
  float gain;           // what the tonemap pass multiplies by
  uint weight;          // the weight measured (0: no pixel with Y > 0)
  uint pad0;
  uint pad1;
};

// The metered target: the key exposure, held down by the highlight guard.
HC_FUNCTION float meteredStops(float meanLog2, float highlightLog2, ExposurePush p) {
  HC_PRECISE float key = p.keyLog2 - meanLog2;
  HC_PRECISE float guard = p.highlightLog2 - highlightLog2;
  HC_PRECISE float pulled = key - kMeterMaxHighlightPull;
  return clamp(max(min(key, guard), pulled), -p.maxStops, p.maxStops);
}

// The stops a frame uses: fixed, or the target eased from the previous
// frame's (kept as it was when nothing was measured).
HC_FUNCTION float exposureStops(uint weight, float target, ExposurePush p) {
  if (p.automatic == 0u) return p.fixedStops;
  if (weight == 0u) return p.hasPrevious != 0u ? p.previousStops : 0.0f;
  if (p.hasPrevious == 0u) return target;
  HC_PRECISE float eased = p.previousStops + clamp(p.adaptation, 0.0f, 1.0f) * (target - p.previousStops);
  return eased;
}

// Per pixel: the weight a pixel of luminance y = meterLuminance(c) adds to
// the bins of meterBin(y) and meterBin(meterPeak(c)), object or not. Black
// pixels (shadowed, or a black backdrop) carry no exposure information;
// neither do NaN and ∞: weight 0.
HC_FUNCTION uint meterWeight(float y, bool object) {
  if (!(y > 0.0f) || isinf(y)) return 0u;
  return object ? kMeterObjectWeight : kMeterBackdropWeight;
}

// The frame's measure and exposure from its two histograms, read in a
// fixed order (so the float sum is the same on both sides). The counts are
// the caller's: in C++ the arrays `luminance` and `peak` of the argument
// (render::ExposureHistograms); in GLSL the shader defines
// meterLuminanceCount(bin) and meterPeakCount(bin) (exposure.comp: its
// shared histograms).
#ifdef __cplusplus
template <class Histograms>
inline ExposureResult meterReadout(const Histograms& h, ExposurePush p) {
#define HC_LUMINANCE_COUNT(bin) h.luminance[bin]
#define HC_PEAK_COUNT(bin) h.peak[bin]
#else
uint meterLuminanceCount(uint bin);
uint meterPeakCount(uint bin);
ExposureResult meterReadout(ExposurePush p) {
#define HC_LUMINANCE_COUNT(bin) meterLuminanceCount(bin)
#define HC_PEAK_COUNT(bin) meterPeakCount(bin)
#endif
  uint total = 0u;
  HC_PRECISE float sumLog2 = 0.0f;
  for (uint b = 0u; b < kMeterBins; ++b) {
    total += HC_LUMINANCE_COUNT(b);
    sumLog2 += float(HC_LUMINANCE_COUNT(b)) * meterBinLog2(b);
  }
  ExposureResult r;
  r.logAverage = 0.0f;
  r.meanLog2 = 0.0f;
  r.highlightLog2 = 0.0f;
  float target = 0.0f;
  if (total != 0u) {
    r.meanLog2 = sumLog2 / float(total);
    const uint need = meterHighlightWeight(total);
    uint above = 0u, bin = kMeterBins - 1u;
    for (; bin > 0u; --bin) {
      above += HC_PEAK_COUNT(bin);
      if (above >= need) break;
    }
    r.highlightLog2 = meterBinLog2(bin);
    r.logAverage = exp2(r.meanLog2);
    target = meteredStops(r.meanLog2, r.highlightLog2, p);
  }
  r.weight = total;
  r.stops = exposureStops(total, target, p);
  r.gain = p.automatic != 0u ? exp2(r.stops) : 1.0f;
  r.pad0 = 0u;
  r.pad1 = 0u;
  return r;
}
#undef HC_LUMINANCE_COUNT
#undef HC_PEAK_COUNT

#endif  // HAARCAST_CORE_SHARED_EXPOSURE_H
