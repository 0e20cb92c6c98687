// The numbers and small functions that the CPU and the shaders share, in one
// header compiled both as C++ (namespace haarcast::shared) and as GLSL
// (shaders include it with GL_GOOGLE_include_directive, -I server/core/include).
// What may be written here, and the HC_ macros: shared_language.h. The GPU
// tests check the shaders' results against the C++ use of the same lines
// (SharedLayout.*).
#ifndef HAARCAST_CORE_SHARED_LAYOUT_H
#define HAARCAST_CORE_SHARED_LAYOUT_H

#include "haarcast/core/shared_language.h"

#ifdef __cplusplus
namespace haarcast::shared {
#endif

// π, written once: kPi for the C++ double paths (core/sphere_map.h takes
// it from here), kPiF and kTwoPiF for the float paths, CPU kernels and
// shaders alike (2π is exact as twice the float of π).
#define HC_PI 3.14159265358979323846
#ifdef __cplusplus
inline constexpr double kPi = HC_PI;
#endif
HC_CONST float kPiF = float(HC_PI);
HC_CONST float kTwoPiF = 2.0f * kPiF;

// Map levels every per-pixel method accepts (level n = 2^n × 2^n).
HC_CONST uint kMinLevel = 2u;
// `fused` on both backends: at level 7 a map is 16,384 pixels.
HC_CONST uint kFusedMaxLevel = 7u;
// The rotating methods on the Vulkan backend (rotate_*.comp): a workgroup
// keeps one map in shared memory, and a level-6 map (16 KiB) is the most
// Vulkan guarantees room for.
HC_CONST uint kRotationMaxLevel = 6u;

// Antialiasing (RenderOptions::antialias): a pixel is an edge pixel when the
// centre samples of its 3×3 neighbourhood do not all see the same object
// (or all none). An edge pixel is the mean of kSubsamples samples at
// (±kSubsampleOffset, ±kSubsampleOffset) pixels from its centre, sample k
// taking + in x when k & 1 and + in y (down) when k & 2: the pixel centres
// of the frame at twice the resolution. Each is shaded alone, or shows the
// backdrop where it misses.
HC_CONST uint kSubsamples = 4u;
HC_CONST float kSubsampleOffset = 0.25f;

// The Vulkan backend's antialiasing (rotation_input.comp, resolve.comp).
// Sub-sample k of pixel (x, y) is pixel (2x + (k & 1), 2y + (k >> 1)) of the
// G-buffer rasterised at twice the resolution: its centre lies at
// (x + ½ ± ¼, y + ½ ± ¼), the sub-sample above. A shaded sample's radiance
// goes to slot y·width + x (a pixel's centre) or, for sub-sample k of an
// edge pixel, to pixels + kSubsamples·(y·width + x) + k. The per-pixel edge
// word is 0 for an interior pixel, else kEdgeFlag | bit k for each covered k.
HC_CONST uint kEdgeFlag = 16u;

HC_FUNCTION uint subsampleSlot(uint pixels, uint pixel, uint k) { return pixels + kSubsamples * pixel + k; }

HC_FUNCTION uint subsampleRasterIndex(uint width, uint x, uint y, uint k) {
  return (2u * y + (k >> 1u)) * (2u * width) + 2u * x + (k & 1u);
}

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

// The point lights' lookup of a slice (fused.h FusedPointLight). A slice
// texel is the mean of ρ·cos over its solid angle (BrdfSliceTable), which
// is what the pass over the map's directions sums. A point light wants ρ at
// one direction, and a bilinear blend of means blurs a lobe twice, by the
// texel and by the tent between centres: a sun's highlight on ggx:0.3 at
// level 6 came out low at its peak and high on its tail (docs/design.md,
// "Point lights read points"). So point lights read the point table
// (PixelSlices::pointSlice: each mean less a 24th of its discrete
// Laplacian, the value at the texel's centre to second order) through
// Catmull-Rom's cubic, which passes through those values: taps at −1, 0,
// +1, +2 about the floor of the position, weighted for its fraction t.
HC_FUNCTION vec4 catmullRomWeights(float t) {
  const float t2 = t * t;
  const float t3 = t2 * t;
  return vec4(0.5f * (2.0f * t2 - t3 - t), 0.5f * (3.0f * t3 - 5.0f * t2 + 2.0f), 0.5f * (4.0f * t2 - 3.0f * t3 + t),
              0.5f * (t3 - t2));
}

// The point value at a texel's centre from its mean and its four
// neighbours' (rows clamped at the poles, columns wrapped, as the lookups
// take them): m − ∇²m/24, the midpoint rule's second-order term. Never
// below zero, as ρ·cos is not (near the horizon the correction overshoots).
HC_FUNCTION float pointFromMean(float mean, float up, float down, float left, float right) {
  return max(mean - (up + down + left + right - 4.0f * mean) / 24.0f, 0.0f);
}

HC_FUNCTION SliceBlend sliceBlendAt(float thetaOut, uint thetaSamples, uint interpolate) {
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

// ---- The Haar quadrant layout and the block quadtree (DESIGN.md "Haar",
// core/haar.h). Detail level l of an m×m map is a 2^l × 2^l grid of
// blocks; band 0 = horizontal (h), 1 = vertical (v), 2 = diagonal (d).

// Index of a detail coefficient in the quadrant layout of an m×m Haar map
// (HaarMap::detailIndexOf): level l, block (i, j); h at rows [0, 2^l),
// columns [2^l, 2^(l+1)); v below the scaling block; d diagonally.
HC_CONSTEXPR uint haarDetailIndex(uint m, uint band, uint l, uint i, uint j) {
  const uint blocks = 1u << l;
  const uint row = i + (band == 0u ? 0u : blocks);
  const uint col = j + (band == 1u ? 0u : blocks);
  return row * m + col;
}

// Where detail coefficient `index` (≥ 1; 0 is the scaling coefficient) of a
// level-n map sits: the inverse of haarDetailIndex. The detail level is that
// of the larger of row and column, the band says which of them lies in the
// upper half of [0, 2^(l+1)).
struct HaarDetailPosition {
  uint band;
  uint level;
  uint i;
  uint j;
};

HC_CONSTEXPR HaarDetailPosition haarDetailPosition(uint mapLevel, uint index) {
  const uint row = index >> mapLevel;
  const uint col = index & ((1u << mapLevel) - 1u);
  const uint l = uint(findMSB(max(row, col)));
  const uint blocks = 1u << l;
  HaarDetailPosition p;
  p.level = l;
  if (row < blocks) {
    p.band = 0u;
    p.i = row;
    p.j = col - blocks;
  } else if (col < blocks) {
    p.band = 1u;
    p.i = row - blocks;
    p.j = col;
  } else {
    p.band = 2u;
    p.i = row - blocks;
    p.j = col - blocks;
  }
  return p;
}

// The quadrant of block (i, j) within its parent: 2·rowBit + colBit
// (0 top-left, 1 top-right, 2 bottom-left, 3 bottom-right).
HC_CONSTEXPR uint haarChildQuadrant(uint i, uint j) { return 2u * (i & 1u) + (j & 1u); }

// Signs of (h, v, d) in the synthesis of child `quadrant` from its parent
// (haar.cpp synthesisStep): S_child = (S + s_h·h + s_v·v + s_d·d) / 2. h
// differs along φ (minus on the right), v along θ (minus at the bottom),
// d is their product.
HC_FUNCTION vec3 haarChildSign(uint quadrant) {
  const float h = 1.0f - 2.0f * float(quadrant & 1u);
  const float v = 1.0f - 2.0f * float(quadrant >> 1u);
  return vec3(h, v, h * v);
}

// The low 16 bits of x moved to the even bits (bit b → bit 2b), and back.
HC_CONSTEXPR uint haarSpreadBits(uint x) {
  x &= 0xFFFFu;
  x = (x | (x << 8u)) & 0x00FF00FFu;
  x = (x | (x << 4u)) & 0x0F0F0F0Fu;
  x = (x | (x << 2u)) & 0x33333333u;
  x = (x | (x << 1u)) & 0x55555555u;
  return x;
}
HC_CONSTEXPR uint haarGatherBits(uint x) {
  x &= 0x55555555u;
  x = (x | (x >> 1u)) & 0x33333333u;
  x = (x | (x >> 2u)) & 0x0F0F0F0Fu;
  x = (x | (x >> 4u)) & 0x00FF00FFu;
  x = (x | (x >> 8u)) & 0x0000FFFFu;
  return x;
}

// Map levels whose preorder keys fit 32 bits: the Morton code of a finest
// block takes 2(n − 1) bits and the level 4 more.
HC_CONST uint kMaxPreorderLevel = 15u;

// Position of block (l, i, j) of a level-n map (finestLevel = n − 1) in a
// pre-order walk of the block quadtree: the Morton code of its top-left
// finest block (row bits odd, column bits even), shifted left by 4 with l
// below, so that a block comes before its descendants and ties (a block and
// its top-left descendants) put the coarser first. The triple product walks
// sparse lists in this order (core triple_product.cpp, triple_product.comp).
HC_CONSTEXPR uint haarPreorderKey(uint finestLevel, uint l, uint i, uint j) {
  const uint shift = finestLevel - l;
  const uint morton = (haarSpreadBits(i << shift) << 1u) | haarSpreadBits(j << shift);
  return (morton << 4u) | l;
}

// The block a preorder key names (the inverse of haarPreorderKey).
struct HaarBlock {
  uint level;
  uint i;
  uint j;
};

HC_CONSTEXPR HaarBlock haarPreorderBlock(uint finestLevel, uint key) {
  HaarBlock b;
  b.level = key & 15u;
  const uint morton = key >> 4u;
  const uint shift = finestLevel - b.level;
  b.i = haarGatherBits(morton >> 1u) >> shift;
  b.j = haarGatherBits(morton) >> shift;
  return b;
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
  float tanHalf;       // tan(½ vertical field of view) of this frame (render::cameraBasis)
  float aspect;        // width / height
  uint antialias;      // 1: edge pixels take kSubsamples sub-samples (above)
  uint background;     // 1: the environment behind the objects, 0: black
  uint width;
  uint height;
  uint backgroundLevel;
  uint fusedGroups;    // `fused`: the most workgroups its indirect dispatch gets (0: not fused)
};

// Per object: object → world rotation (columns), where its slices, method
// data, vertices and triangles start; for `fused` its own map level and
// where its level's data start in the buffers every object shares (objects
// at different levels lie side by side: docs/design.md, "A level per object").
struct ObjectInfo {
  vec4 rotation[3];
  uint sliceBase;      // global slice index of its θ slice 0
  uint methodBase;     // words into the method data
  uint thetaSamples;   // T
  uint vertexBase;     // its vertex 0 in the global vertex numbering
  uint triangleBase;   // its triangle 0 in the global triangle numbering
  float skipBelowY;    // `fused`: directions with cos θ' below this read only zero texels
  uint pointLights;    // `fused`: its PointLight records this frame (≤ kMaxPointLights)
  uint flags;          // kObjectGround, …
  vec4 groundRadiance; // a ground object: the radiance of its unshadowed map light (rgb)
  vec4 toLight[3];     // `fused`'s lobe path: object frame → the environment's, this frame (columns)
  // x: cos of the lobe path's core angle (core fused.h LobePath::coreAngle),
  // −1: the path takes all; y: the smooth sum's cos limit between mirror
  // directions (shared_smooth.h smoothMirrorCos of its sharpest median lobe
  // angle, core PreparedObject::sharpestLobe); zw: 0
  vec4 lobeCore;
  uint level;          // `fused`: its map level n (M = 2^n, N = M² directions)
  uint texelBase;      // `fused`: texel of its slice 0 in the slice texels; slice t at texelBase + t·N
  uint lightBase;      // `fused`: texel of its light's direction 0 this frame
  uint directionBase;  // `fused`: its level's pixel-centre directions in the table of every level in use
  uint visibilityBase; // `fused`: word of its vertex 0's bits; global vertex v at visibilityBase + (v − vertexBase)·visibilityWords(level)
  uint pointLevel;     // `fused`: its point slices' level (core PixelSlices::pointLevel), ≥ level
  uint pointTexelBase; // `fused`: texel of its point slice 0 in the point texels; slice t at pointTexelBase + t·N of pointLevel
  float sumTolerance;  // `fused`: sums by cells at this tolerance (shared_cells.h); 0: every direction
};

// ObjectInfo::flags: the object is the scene's ground, a Lambert plane that
// `fused` shades in closed form (its map light is the same at every point,
// so only the point lights' shadow bits vary): radiance = groundRadiance + Σ_k bit_k·power_k.
HC_CONST uint kObjectGround = 1u;
// ObjectInfo::flags: some of the object's pixels take `fused`'s lobe path
// (their shadow word carries kLobeSeenBit).
HC_CONST uint kObjectLobePath = 2u;
// ObjectInfo::flags: other objects can hide sky from it (the scene has two
// objects or more besides a ground): `fused` reads its samples' HiddenLight
// (shared_rays.h).
HC_CONST uint kObjectSkyHidden = 4u;

// `fused`'s point lights (core/light_split.h): the light's brightest
// regions, shaded per pixel with a shadow ray each. Records per object and
// light at [object·kMaxPointLights + k]: `direction` (xyz) toward the light in
// the object's frame; `power` (rgb) = Σ L·ΔΩ of the texels the light took
// (for a ground object instead the radiance it adds where seen:
// albedo/π·cos θ·power). Each covered sample s has a word of shadow bits,
// bit k = 1 when the sample sees light k (render/point_lights.h computes
// them on the host for both backends).
HC_CONST uint kMaxPointLights = 16u;
// A ground sample's word carries, above the light bits, the share of its
// map light that the scene's objects hide (render/point_lights.h,
// groundSkyOcclusion) in 16 bits: radiance = (1 − share)·groundRadiance +
// Σ_k bit_k·power_k.
HC_CONST uint kGroundOcclusionShift = 16u;
HC_CONST float kGroundOcclusionSteps = 65535.0;
HC_FUNCTION float groundSkyKept(uint word) {
  return 1.0 - float(word >> kGroundOcclusionShift) / kGroundOcclusionSteps;
}
struct PointLight {
  vec4 direction;
  vec4 power;
};

// ---- The lobe path of `fused` and the `splitsum` method (core/lobe.h,
// core/prefiltered_light.h). A lobe narrower than the map's texels is not
// summed over the map's directions but integrated over its own: I_c =
// E_c·Σ_i w_i·L_c(ω_i)·V(a), E_c = ∫ρ_c dω of the lobe (or of its core),
// a the lobe's axis (the mirror direction), and the samples ω_i stratified
// by the lobe's own distribution, measured from the BRDF: kLobeBands radial
// bands whose edges double outward from half the median angle, each cut
// into kLobeSectors equal shares of its energy in azimuth, one sample at
// each share's median, weighted by the share's energy w_i. Each reads the
// light prefiltered to its share's solid angle (level λ_i, trilinear), so
// the samples see all of the light, not points of it (filtered importance
// sampling).
HC_CONST uint kLobeSectors = 8u;    // J
HC_CONST uint kLobeBands = 8u;      // the lobe path's radial bands (samples)
HC_CONST uint kLobeSamples = kLobeBands * kLobeSectors;

// One slice's lobe, measured from the BRDF itself (core/lobe.h).
struct SliceLobe {
  vec4 energy;   // rgb: ∫ρ_c dω (cos θᵢ included); a: the axis' θ, local direction (0, cos θ, −sin θ)
  vec4 median;   // x: the angle holding half the energy; yzw: 0
  vec4 core;     // rgb: ∫ρ_c dω within the core angle (the lobe path's part of the energy); a: 0
  // Sample kJ + j of the lobe path: (a, b, λ, w), the angle a from the
  // axis, the azimuth b from u = (1, 0, 0) toward v = axis × u = (0, −sin θ,
  // −cos θ), the prefiltered level λ of its stratum's solid angle, and its
  // share w of the energy (Σ w = 1).
  vec4 samples[kLobeSamples];
};

// The lobe of θₒ between two slices: each field linear in the blend weight.
HC_FUNCTION SliceLobe blendLobes(SliceLobe a, SliceLobe b, float t) {
  SliceLobe l;
  l.energy = a.energy + t * (b.energy - a.energy);
  l.median = a.median + t * (b.median - a.median);
  l.core = a.core + t * (b.core - a.core);
  for (uint i = 0u; i < kLobeSamples; ++i) l.samples[i] = a.samples[i] + t * (b.samples[i] - a.samples[i]);
  return l;
}

// Sample j of ring k: its azimuth about the axis in sector units (odd rings
// turned by half a sector, so the rings' samples do not line up).
HC_FUNCTION float lobeAzimuthSectors(uint k, uint j) { return float(j) + 0.5f + 0.5f * float(k & 1u); }

// Where level l of a prefiltered light starts: levels 0 … l − 1 before it,
// 4^k texels each. Levels 0 … kPrefilterLevels − 1.
HC_CONST uint kPrefilterLevels = 11u;
HC_FUNCTION uint prefilterOffset(uint level) { return ((1u << (2u * level)) - 1u) / 3u; }

// The rows of `fused`'s pass (fused_kernel.cpp, fused.comp): only those
// that can reach the slices' non-zero cap. y2 = ω·a with a = (sin β sin α,
// cos β, sin β cos α) at angle β from +Y, so y2 ≥ skipBelowY needs ω within
// δ = acos(skipBelowY) of a, and a pixel centre at θᵢ is at least |θᵢ − β|
// from it; the margin covers float rounding, so every direction of the
// other rows reads zero texels. x: the first row, y: the end (exclusive).
// The pass's directions per sample are (y − x)·M (bench-frame reports them).
HC_FUNCTION uvec2 passRows(uint m, float cosBeta, float skipBelowY) {
  if (!(skipBelowY > -1.0f)) return uvec2(0u, m);
  const float rowScale = float(m) / kPiF;
  const float axis = HC_ACOS(clamp(cosBeta, -1.0f, 1.0f));
  const float reach = HC_ACOS(min(skipBelowY, 1.0f)) + 2e-3f;
  return uvec2(uint(clamp(floor((axis - reach) * rowScale - 0.5f), 0.0f, float(m))),
               uint(clamp(ceil((axis + reach) * rowScale - 0.5f) + 1.0f, 0.0f, float(m))));
}

// Bilinear taps at (θ, φ) on a level-`level` lat-long map (core
// bilinearTaps, in float): θ clamps at the poles, φ wraps.
struct LatLongTaps {
  uint row0;
  uint row1;
  uint col0;
  uint col1;
  float tRow;
  float tCol;
};
HC_FUNCTION LatLongTaps latLongTaps(uint level, float theta, float phi) {
  const uint m = 1u << level;
  const float y = clamp(theta * (float(m) / kPiF) - 0.5f, 0.0f, float(m - 1u));
  const float x = phi * (float(m) / (2.0f * kPiF)) - 0.5f;
  const float fy = floor(y), fx = floor(x);
  LatLongTaps t;
  t.tRow = y - fy;
  t.tCol = x - fx;
  t.row0 = uint(fy);
  t.row1 = min(t.row0 + 1u, m - 1u);
  t.col0 = uint(int(fx) & int(m - 1u));
  t.col1 = (t.col0 + 1u) & (m - 1u);
  return t;
}

// ---- `splitsum` (core/splitsum.h): the image-based lighting of real-time
// engines, one lookup of the prefiltered light per pixel instead of the lobe
// path's K·J. I_c = E_c(θₒ)·L_c(λ, m)·V(m): m the mirror direction, V its
// shadow ray (kLobeSeenBit), and λ the level whose texel has the solid
// angle of the disc of the lobe's median angle a, π·a² = 2π²/M² (a level-n
// texel at the equator is (π/M)·(2π/M), M = 2^n): M = √(2π)/a. A bilinear
// lookup of box-filtered texels of side s spreads like a Gaussian of σ = s/2,
// whose median radius 1.18σ then matches a with s² ≈ π·a² to 10 %: the
// texel's footprint has the lobe's spread, not its support. λ is
// fractional (trilinear) and clamped to the light's levels.
HC_CONST float kSqrtTwoPi = 2.50662827463100050f;
HC_CONST float kSplitsumMinAngle = 1e-6f;
HC_FUNCTION float splitsumLevel(float medianAngle) {
  return log2(kSqrtTwoPi / max(medianAngle, kSplitsumMinAngle));
}

// A sample's shadow word, for an object with a lobe path (not a ground):
// bit kLobeSeenBit set when the ray along its mirror direction escapes.
HC_CONST uint kLobeSeenBit = 1u << 16u;

// `fused`'s visibility (core/visibility_bits.h): vertex v's bits at words
// [v·W, (v + 1)·W), W = visibilityWords(level), direction i at bit i % 32 of word i / 32.
HC_FUNCTION uint visibilityWords(uint level) { return max((1u << (2u * level)) / 32u, 1u); }

// Per covered pixel, what the rotation needs (the rotation contract's kRotateSamplesBinding, shared_passes.h).
struct RotationSample {
  uint slice;          // global slice: the object's slice base + nearest θ slice
  uint methodBase;     // the object's offset into the method data, in words
  float alpha;         // Y-X-Y Euler angles: R = Ry(α) Rx(β) Ry(γ) (core/rotation.h)
  float beta;
  float gamma;
  uint pixel;          // its radiance slot: y·width + x, or subsampleSlot (above)
  float thetaOut;      // θₒ, for the slice blend of `fused`
  uint pad;
};

// Per covered pixel, what the product needs besides the rotated slice.
struct ShadeSample {
  uint object;
  uint vertex[3];      // global vertex ids of the hit triangle
  float b[3];          // barycentrics (b0 = 1 − u − v, b1 = u, b2 = v)
  uint pixel;          // its radiance slot, as RotationSample::pixel
};

// Auto exposure's metering, ExposurePush and ExposureResult.
#include "haarcast/core/shared_exposure.h"

// Shadow rays on the device: RayObject, RayFrame, RaysPush.
#include "haarcast/core/shared_rays.h"

// The passes' workgroup sizes, push blocks and bindings.
#include "haarcast/core/shared_passes.h"

// `fused`'s light resolved on the device: LightPush, its phases and bindings.
#include "haarcast/core/shared_light.h"

#ifdef __cplusplus
static_assert(sizeof(FrameParams) == 128 && offsetof(FrameParams, tanHalf) == 96 &&
              offsetof(FrameParams, fusedGroups) == 124);
static_assert(sizeof(ObjectInfo) == 192 && offsetof(ObjectInfo, toLight) == 96 && offsetof(ObjectInfo, sliceBase) == 48 &&
              offsetof(ObjectInfo, skipBelowY) == 68 && offsetof(ObjectInfo, groundRadiance) == 80 &&
              offsetof(ObjectInfo, level) == 160 && offsetof(ObjectInfo, visibilityBase) == 176);
static_assert(sizeof(PointLight) == 32);
static_assert(sizeof(RayObject) == 144 && offsetof(RayObject, sphere) == 112 && offsetof(RayObject, occluder) == 140);
static_assert(sizeof(RayFrame) == 400 && offsetof(RayFrame, eye) == 256 && offsetof(RayFrame, toEnvironment) == 288 &&
              offsetof(RayFrame, lights) == 336 && offsetof(RayFrame, objectSky) == 380 && offsetof(RayFrame, fineRows) == 392 &&
              offsetof(RayFrame, skyJobCapacity) == 396);
static_assert(sizeof(SkyJob) == 8);
static_assert(sizeof(HiddenLight) == 16 && offsetof(HiddenLight, direction) == 12);
static_assert(sizeof(SliceLobe) == 48 + 16 * kLobeSamples && offsetof(SliceLobe, median) == 16 &&
              offsetof(SliceLobe, core) == 32 && offsetof(SliceLobe, samples) == 48);
static_assert(kLobeSeenBit >= (1u << kMaxPointLights), "the lobe's bit lies above the light bits");
static_assert(kMaxPointLights <= kGroundOcclusionShift, "the light bits and the ground's occlusion share one word");
static_assert(sizeof(RotationSample) == 32 && offsetof(RotationSample, alpha) == 8 &&
              offsetof(RotationSample, thetaOut) == 24);
static_assert(sizeof(ShadeSample) == 32 && offsetof(ShadeSample, b) == 16 && offsetof(ShadeSample, pixel) == 28);
static_assert(sizeof(CoverageCounter) == 16 && offsetof(CoverageCounter, groups) == 4);
static_assert(sizeof(DispatchArgs) == 16 && offsetof(DispatchArgs, groups) == 0);
static_assert(sizeof(ExposurePush) == 32 && sizeof(ExposureResult) == 32);
static_assert(sizeof(GBufferPush) == 80 && offsetof(GBufferPush, objectId) == 64);
static_assert(sizeof(RotationPush) == 16 && offsetof(RotationPush, count) == 4);
static_assert(sizeof(BatchArgsPush) == 16 && offsetof(BatchArgsPush, batches) == 4);
static_assert(sizeof(LightPush) == 64 && offsetof(LightPush, restDirections) == 16 && offsetof(LightPush, groundUp) == 32 &&
              offsetof(LightPush, albedo) == 48);
#endif

#ifdef __cplusplus
}  // namespace haarcast::shared
#endif
#undef HC_PI

#endif  // HAARCAST_CORE_SHARED_LAYOUT_H
