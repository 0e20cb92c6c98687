// The display encoding's search, shared by the CPU (render::tonemapByte,
// render/tonemap.h) and the device (shaders/tonemap.comp): a linear value's
// 8-bit code is the number of code boundaries it reaches. The boundaries
// (render::tonemapThresholds) are computed once per frame on the host, in
// double; counting them needs no pow, which Vulkan lets a device compute
// loosely, so both sides give the same byte for every float.
#ifndef HAARCAST_CORE_SHARED_TONEMAP_H
#define HAARCAST_CORE_SHARED_TONEMAP_H

#include "haarcast/core/shared_layout.h"

#ifdef __cplusplus
namespace haarcast::shared {
#endif

// Codes 0 … kToneCodes − 1; threshold[k], k ≥ 1, is the least value whose
// code is ≥ k (threshold[0] is unused).
HC_CONST uint kToneCodes = 256u;

// The largest k with value ≥ threshold[k] (0 when none, and for NaN, whose
// comparisons are false), by binary search. The thresholds are the caller's:
// in C++ the table given; in GLSL the shader defines toneThreshold(k)
// (tonemap.comp: its threshold buffer).
#ifdef __cplusplus
template <class Thresholds>
inline uint tonemapCode(float value, const Thresholds& threshold) {
#define HC_TONE_THRESHOLD(k) threshold[k]
#else
float toneThreshold(uint k);
uint tonemapCode(float value) {
#define HC_TONE_THRESHOLD(k) toneThreshold(k)
#endif
  uint code = 0u;
  for (uint step = kToneCodes / 2u; step > 0u; step >>= 1u) {
    const uint next = code + step;
    if (next < kToneCodes && value >= HC_TONE_THRESHOLD(next)) code = next;
  }
  return code;
}
#undef HC_TONE_THRESHOLD

#ifdef __cplusplus
}  // namespace haarcast::shared
#endif

#endif  // HAARCAST_CORE_SHARED_TONEMAP_H
