// The numbers and small functions that the CPU and the shaders share, in one
// header compiled both as C++ (namespace haarcast::shared) and as GLSL
// (shaders include it with GL_GOOGLE_include_directive, -I server/core/include).
// Write only what both languages read alike: plain structs of uint, float and
// vec4, `const` numbers, and functions built from floor/min/clamp. The GPU
// tests check the shaders' results against the C++ use of the same lines.
#ifndef HAARCAST_CORE_SHARED_LAYOUT_H
#define HAARCAST_CORE_SHARED_LAYOUT_H

#ifdef __cplusplus
#include <algorithm>
#include <cmath>
#include <cstdint>

namespace haarcast::shared {
using uint = std::uint32_t;
using std::clamp;
using std::floor;
using std::min;
#define HC_CONST inline constexpr
#else
#define HC_CONST const
#endif

// π in float, for the float paths (CPU kernels and shaders alike).
HC_CONST float kPiF = 3.14159265358979323846f;

// Map levels every per-pixel method accepts (level n = 2^n × 2^n).
HC_CONST uint kMinLevel = 2u;
// `fused` on both backends: at level 7 a map is 16,384 pixels.
HC_CONST uint kFusedMaxLevel = 7u;

// A BRDF slice in pixel form, as `fused` samples it: texel (row, col) of
// slice t at ((t·M + row)·M + col)·kTexelFloats, holding R, G, B and a zero.
HC_CONST uint kTexelFloats = 4u;

// θₒ → the BRDF slices to use: ρ = (1 − weight)·slice[first] + weight·slice[second].
// The T samples sit at the centres of T equal cells of [0, π/2],
// θₜ = (t + ½)·(π/2)/T (BrdfSliceTable). Interpolating, the weight is linear
// between neighbouring centres and clamped at the two ends, so the blend is
// continuous in θₒ and equals slice t exactly at θₜ. Without it, the slice
// whose cell holds θₒ (BrdfSliceTable::nearestSlice), weight 0.
struct SliceBlend {
  uint first;
  uint second;
  float weight;
};

#ifdef __cplusplus
inline
#endif
SliceBlend sliceBlendAt(float thetaOut, uint thetaSamples, uint interpolate) {
  const float cells = float(thetaSamples);
  const float u = clamp(thetaOut, 0.0f, 0.5f * kPiF) * (cells / (0.5f * kPiF));  // in cells, [0, T]
  SliceBlend b;
  if (interpolate == 0u) {
    b.first = min(uint(floor(u)), thetaSamples - 1u);
    b.second = b.first;
    b.weight = 0.0f;
    return b;
  }
  const float centred = clamp(u - 0.5f, 0.0f, cells - 1.0f);  // in sample spacings from θ₀
  const float below = floor(centred);
  b.first = uint(below);
  b.second = min(b.first + 1u, thetaSamples - 1u);
  b.weight = centred - below;
  return b;
}

#ifdef __cplusplus
}  // namespace haarcast::shared
#undef HC_CONST
#endif

#endif  // HAARCAST_CORE_SHARED_LAYOUT_H
