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
#include <cstddef>
#include <cstdint>

#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

namespace haarcast::shared {
using uint = std::uint32_t;
using vec4 = glm::vec4;
using mat4 = glm::mat4;
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

// Antialiasing (RenderOptions::antialias): a pixel is an edge pixel when the
// centre samples of its 3×3 neighbourhood do not all see the same object
// (or all none). An edge pixel is the mean of kSubsamples samples at
// (±kSubsampleOffset, ±kSubsampleOffset) pixels from its centre, sample k
// taking + in x when k & 1 and + in y (down) when k & 2: the pixel centres
// of the frame at twice the resolution. Each is shaded alone, or shows the
// backdrop where it misses.
HC_CONST uint kSubsamples = 4u;
HC_CONST float kSubsampleOffset = 0.25f;

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

// Index of a detail coefficient in the quadrant layout of an m×m Haar map
// (HaarMap::detailIndexOf): band 0 = horizontal, 1 = vertical, 2 = diagonal;
// level l, block (i, j).
#ifdef __cplusplus
inline constexpr
#endif
uint haarDetailIndex(uint m, uint band, uint l, uint i, uint j) {
  const uint blocks = 1u << l;
  const uint row = i + (band == 0u ? 0u : blocks);
  const uint col = j + (band == 1u ? 0u : blocks);
  return row * m + col;
}

// ---- Records the Vulkan passes exchange (std430; the C++ side checks sizes
// and offsets below). Zero-initialise them on the host (`T x{}`): GLSL has no
// member initialisers.

// The camera of render::CameraRays and the frame's settings (every pass).
struct FrameParams {
  vec4 forward;        // xyz
  vec4 right;          // xyz
  vec4 up;             // xyz
  vec4 lightRotT[3];   // columns of lightRotationᵀ (xyz)
  float tanHalf;       // tan(fovY / 2)
  float aspect;        // width / height
  float gain;          // 2^exposureStops
  uint background;     // 1: the environment behind the objects, 0: black
  uint width;
  uint height;
  uint backgroundLevel;
  uint fusedGroups;    // `fused`: the most workgroups its indirect dispatch gets (0: not fused)
};

// Per object: object → world rotation (columns), where its slices, method
// data, vertices and triangles start.
struct ObjectInfo {
  vec4 rotation[3];
  uint sliceBase;      // global slice index of its θ slice 0
  uint methodBase;     // words into the method data
  uint thetaSamples;   // T
  uint vertexBase;     // its vertex 0 in the global vertex numbering
  uint triangleBase;   // its triangle 0 in the global triangle numbering
  float skipBelowY;    // `fused`: directions with cos θ' below this read only zero texels
  uint blendRows;      // `fused`: the slice rows such directions can reach (the last non-zero row + 3, ≤ M)
  uint pad;
};

// Per covered pixel, what the rotation needs (the rotation contract's binding 0).
struct RotationSample {
  uint slice;          // global slice: the object's slice base + nearest θ slice
  uint methodBase;     // the object's offset into the method data, in words
  float alpha;         // Y-X-Y Euler angles: R = Ry(α) Rx(β) Ry(γ) (core/rotation.h)
  float beta;
  float gamma;
  uint pixel;          // y·width + x
  float thetaOut;      // θₒ, for the slice blend of `fused`
  uint pad;
};

// Per covered pixel, what the product needs besides the rotated slice.
struct ShadeSample {
  uint object;
  uint vertex[3];      // global vertex ids of the hit triangle
  float b[3];          // barycentrics (b0 = 1 − u − v, b1 = u, b2 = v)
  uint pixel;          // y·width + x
};

// The rotation-input pass's counter, followed by the indirect dispatch
// arguments of `fused` (VkDispatchIndirectCommand at byte 4): groups[0] =
// min(covered, FrameParams::fusedGroups), groups[1] = groups[2] = 1 once
// any pixel is covered.
struct CoverageCounter {
  uint covered;
  uint groups[3];
};

// The G-buffer pass's push block (gbuffer.vert / .frag).
struct GBufferPush {
  mat4 objectToClip;
  uint objectId;
  uint triangleBase;
  uint pad0;
  uint pad1;
};

#ifdef __cplusplus
static_assert(sizeof(FrameParams) == 128 && offsetof(FrameParams, tanHalf) == 96 &&
              offsetof(FrameParams, fusedGroups) == 124);
static_assert(sizeof(ObjectInfo) == 80 && offsetof(ObjectInfo, sliceBase) == 48 &&
              offsetof(ObjectInfo, skipBelowY) == 68 &&
              offsetof(ObjectInfo, blendRows) == 72);
static_assert(sizeof(RotationSample) == 32 && offsetof(RotationSample, alpha) == 8 &&
              offsetof(RotationSample, thetaOut) == 24);
static_assert(sizeof(ShadeSample) == 32 && offsetof(ShadeSample, b) == 16 && offsetof(ShadeSample, pixel) == 28);
static_assert(sizeof(CoverageCounter) == 16 && offsetof(CoverageCounter, groups) == 4);
static_assert(sizeof(GBufferPush) == 80 && offsetof(GBufferPush, objectId) == 64);
#endif

#ifdef __cplusplus
}  // namespace haarcast::shared
#undef HC_CONST
#endif

#endif  // HAARCAST_CORE_SHARED_LAYOUT_H
