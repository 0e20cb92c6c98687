#version 450
// The "fused" pass (core/fused.h, fused_kernel.cpp): per covered sample,
//   I_c = Σ_ω W_c(ω)·ρ_c(Rᵀω) + Σ_k bit_k·power_k,c·ρ_c(Rᵀd_k),
//   W_c = (L_c·ΔΩ)(ω)·V(ω),
// the rotation and the triple product in one sum over the M² map directions
// (equal by Parseval to `spatial` followed by the Haar triple product), plus
// the point lights the sample sees (core/light_split.h; its shadow bits are
// computed on the host, render/point_lights.h). A ground object
// (ObjectInfo::flags & kObjectGround) is shaded in closed form instead:
// radiance = groundRadiance + Σ_k bit_k·power_k, no direction loop.
//
// One workgroup per covered sample at a time; workgroups loop over the
// compacted samples (s = group, group + groups, …), so the dispatch is sized
// by the rotation-input pass's indirect arguments. With a smooth-sum
// tolerance (push.stage ≠ kSmoothSumOff; core/shared_smooth.h) the pass is
// dispatched once per stage, coarse to fine: each visits its stage's pixels
// (and stage 0 every sample the smooth sum does not visit), from the lists
// a dispatch before them writes (listStages), in two dispatches: an
// invocation a sample decides (decideStage), a workgroup a sample sums
// what it could not take; a pixel
// whose parents allow takes their mean sum instead of steps 1–2. Per sample:
//   1. the invocations stride over the directions: Rᵀω with R = Ry(α)Rx(β)Ry(γ)
//      (γ only offsets the source column), θ', φ' with the CPU kernel's
//      atan2, ρ bilinear in the slice texels exactly as bilinearTaps (θ
//      clamped, φ wrapped); with two θₒ slices each tap is blended,
//      a + w·(b − a), as fusedShade blends texels (rhoAt); V(ω) is the hit
//      triangle's three vertices' visibility bits blended by the
//      barycentrics, V = b0·bit0 + b1·bit1 + b2·bit2 (core blendVisibility);
//      accumulated with W_c = L_c·V. An object with ObjectInfo::sumTolerance
//      > 0 is summed by cells of 4 × 4 directions instead (sumCells,
//      core/shared_cells.h): one lookup where its slice is smooth, the 16
//      directions where not;
//   2. the partial sums are reduced (subgroupAdd where the workgroup is one
//      subgroup, SUBGROUP_REDUCE; else in invocation order through shared
//      memory, with barriers); invocation 0 puts
//      the lobe's energy back (× ∫ρ / Σ ΔΩ·ρ, the second sum of step 1:
//      core fused.cpp energyKept), takes off the sky other objects hide
//      (lessHiddenSky), adds the point lights whose bit is set, in light
//      order, each with ρ read at the light's direction from the point
//      slices by Catmull-Rom (pointRhoAt: core point_rho_kernel.cpp), and
//      adds the lobe path's core; radiance[pixel] = Σ.
// An object with a lobe path (shared_layout.h, "The lobe path") leaves the
// directions within its core angle of the lobe's axis to it (rhoAt reads
// ρ = 0 there, and the pass's energy is the lobe's less the core's); when
// the path takes the whole lobe, steps 1–2 are skipped and invocation 0
// reads the prefiltered light at the lobe's samples (lobeShade).
//
// Each object has its own map level (ObjectInfo::level: M = 2^n, N = M²
// directions; docs/design.md, "A level per object"): its slices, light,
// visibility words and the pixel-centre directions of its level start at
// its own bases in buffers every object shares, and the loops below take M
// from the sample's object, not from a constant.
//
// The large read-only arrays of step 1 (slice texels, light, directions,
// visibility words) are uniform texel buffers read with texelFetch: on a CPU
// device (lavapipe) a fetch is one vector gather, where a storage-buffer
// read at a per-invocation index goes lane by lane and component by
// component, each behind a branch (docs/gpu.md, "fused on lavapipe").
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_shuffle : require
#extension GL_EXT_control_flow_attributes : require
#include "haarcast/core/shared_layout.h"
#include "haarcast/core/shared_cells.h"
#include "haarcast/core/shared_smooth.h"
#include "common/frame.glsl"
#include "common/sphere.glsl"

layout(local_size_x_id = kSpecLocalSize) in;
layout(constant_id = kSpecInterpolate) const uint INTERPOLATE = 1u;    // RenderOptions::interpolateSlices
layout(constant_id = kSpecPrefilterFinest) const uint PREFILTER_FINEST = 9u;  // the prefiltered light's finest level
layout(constant_id = kSpecSubgroupReduce) const uint SUBGROUP_REDUCE = 0u;     // shared_passes.h
layout(constant_id = kSpecCellsTogether) const uint CELLS_TOGETHER = 0u;       // shared_passes.h

const uint LOCAL = gl_WorkGroupSize.x;

layout(std430, set = 0, binding = kFusedSamplesBinding) readonly buffer Samples { RotationSample samples[]; };
layout(std430, set = 0, binding = kFusedShadeBinding) readonly buffer Shade { ShadeSample shade[]; };
layout(std430, set = 0, binding = kFusedObjectsBinding) readonly buffer Objects { ObjectInfo objects[]; };
// Object o's slice t, direction k at o.texelBase + t·N + k: RGB0.
layout(set = 0, binding = kFusedSliceTexelsBinding) uniform textureBuffer texels;
layout(set = 0, binding = kFusedLightTexelsBinding) uniform textureBuffer light;        // object o, direction k at o.lightBase + k: (L·ΔΩ) RGB, 0
// Global vertex v of object o, direction i: bit i % 32 of word
// o.visibilityBase + (v − o.vertexBase)·visibilityWords(o.level) + i / 32 (core VisibilityBits).
layout(set = 0, binding = kFusedVisibilityTexelsBinding) uniform utextureBuffer visibilityBits;
// Pixel-centre unit vectors (xyz) and ΔΩ (w) of every level in use; level n's direction k at o.directionBase + k.
layout(set = 0, binding = kFusedDirectionTexelsBinding) uniform textureBuffer directions;
// Object o, light k at o·kMaxPointLights + k; ObjectInfo::pointLights of them are this frame's.
layout(std430, set = 0, binding = kFusedPointLightsBinding) readonly buffer PointLights { PointLight pointLights[]; };
layout(std430, set = 0, binding = kFusedRadianceBinding) buffer Radiance { vec4 radiance[]; };
layout(std430, set = 0, binding = kFusedCounterBinding) readonly buffer Counter { CoverageCounter counter; };
layout(std430, set = 0, binding = kFusedMasksBinding) readonly buffer Masks { uint masks[]; };  // sample s: bit k = sees light k
layout(std430, set = 0, binding = kFusedHiddenBinding) readonly buffer Hidden { HiddenLight hidden[]; };  // sample s: the sky other objects hide
layout(std430, set = 0, binding = kFusedSliceEnergyBinding) readonly buffer SliceEnergies { vec4 sliceEnergy[]; };  // global slice: ∫ρ_c (rgb)
layout(std430, set = 0, binding = kFusedLobesBinding) readonly buffer Lobes { SliceLobe lobes[]; };          // global slice: its lobe
// Level l of the prefiltered light at prefilterOffset(l), RGB0 (core PrefilteredLight).
layout(set = 0, binding = kFusedLobeLightTexelsBinding) uniform textureBuffer lobeLight;
// The slices as point values at the texel centres (core PixelSlices::pointSlice), at each object's
// pointLevel: object o's slice t, direction k at o.pointTexelBase + t·N + k.
layout(set = 0, binding = kFusedPointSliceTexelsBinding) uniform textureBuffer pointTexels;
// Per object (kSliceCountsPerObject words from kSliceCountsPerObject·object): its samples shaded
// from one slice (the ground's samples, which read none, too) and from two,
// the pass's rows summed over its samples, the most directions for one, and
// by cells its coarse and its fine cells summed (shared_passes.h), cleared
// before the pass; the host counts the coefficient bytes read (core
// fusedPixelBytes) and the directions summed from them without reading any
// sample back.
layout(std430, set = 0, binding = kFusedSliceCountsBinding) buffer SliceCounts { uint sliceCounts[]; };
// By cells (ObjectInfo::sumTolerance > 0; shared_cells.h): global slice s's
// detail map at s·kCellDetailStride; the light's cells follow the object's
// light texels (cellPowerTexel, cellCentroidTexel), the cells' centres its
// level's directions (cellCentreTexel).
layout(set = 0, binding = kFusedDetailTexelsBinding) uniform textureBuffer details;
// The smooth sum (shared_smooth.h): pixel q's sum and 1 + its object at
// 2q, its mirror direction at 2q + 1, written where it is visited; the
// stage this dispatch visits, the frame's size and the tolerance.
layout(std430, set = 0, binding = kFusedSmoothBinding) buffer Smooth { vec4 smoothData[]; };
// The smooth sum's stage lists (shared_smooth.h smoothListOffset): counts,
// indirect dispatches, samples.
layout(std430, set = 0, binding = kFusedStageListsBinding) buffer StageLists { uint stageLists[]; };
layout(push_constant) uniform Push { FusedPush push; };

shared vec3 partial[LOCAL];
shared vec3 partialSum[LOCAL];  // Σ ΔΩ·ρ_c: the lobe's energy as the directions sample it
shared uint partialCount[LOCAL];  // by cells: the directions summed

void sync() {
  memoryBarrierShared();
  barrier();
}

// What the direction loop needs of a sample.
struct PixelSetup {
  ShadeSample sh;
  uint m;                  // M = 2^n of the object's level
  uint directionBase;      // its level's direction 0
  uint bits0, bits1, bits2;  // the three vertices' visibility word 0
  uint base0, base1;       // the two slices' texel 0 (equal without a blend)
  float weight;            // of the second slice
  uint lightBase;          // the object's light texel 0
  float sinA, cosA, sinB, cosB;
  int shift;               // whole source columns of γ
  float fraction;          // and the fraction
  uint pointM;             // the point slices': M of their level,
  uint pointBase0, pointBase1;  // the two slices' texel 0,
  int pointShift;          // and γ's offset at that level
  float pointFraction;
  float skipBelowY;
  uint firstRow, endRow;   // the rows that can reach the slice's non-zero cap
  vec3 axis;               // the lobe's axis before R_y(−γ), and the lobe path's core (fused.cpp setCore)
  float coreCos;
  float coreCellCos;       // by cells: a cell whose turned centre is nearer the axis is summed fine
  float reachCut;          // by cells: one whose turned centre is below this adds nothing (cellReachCut)
  float tolerance;         // by cells: the detail above which a cell is summed fine
  uint detail0, detail1;   // the two slices' detail maps
};

// γ as a column offset of a map of M = m (core fused.cpp columnOffset):
// source column = φ'·M/2π − (γ·M/2π + ½); the offset's whole part (x)
// shifts the integer column, its fraction (y) the float coordinate.
vec2 columnOffset(float gamma, uint m) {
  float offset = gamma * (float(m) / kTwoPiF) + 0.5;
  offset -= floor(offset / float(m)) * float(m);
  const float whole = floor(offset);
  return vec2(whole, offset - whole);
}

// Texel `index` of ρ: the slice's own, or the blend of the two slices.
vec3 texel(const bool blended, PixelSetup p, uint index) {
  const vec3 a = texelFetch(texels, int(p.base0 + index)).rgb;
  if (!blended) return a;
  const vec3 b = texelFetch(texels, int(p.base1 + index)).rgb;
  return a + p.weight * (b - a);
}

// Where the object-frame direction w0 falls in a slice of M = m: Rᵀw0, θ',
// φ' as continuous texel coordinates (row, column before γ's whole
// columns; `fraction` its fraction at that M), as the CPU kernel computes
// them. False where every tap reads zero: cos θ' below the slices' cut, or
// inside the lobe path's core.
// R_x(−β) R_y(−α) w0 (x₁, y₂, z₂).
vec3 turned(PixelSetup p, vec3 w0) {
  const float x1 = p.cosA * w0.x - p.sinA * w0.z;  // R_y(−α)
  const float z1 = p.sinA * w0.x + p.cosA * w0.z;
  return vec3(x1, p.cosB * w0.y + p.sinB * z1, p.cosB * z1 - p.sinB * w0.y);  // R_x(−β)
}
vec2 positionOf(vec3 t, uint m, float fraction) {
  const float theta = atan2Fast(sqrt(t.x * t.x + t.z * t.z), t.y);
  const float phi = atan2Fast(t.x, t.z);
  return vec2(min(max(theta * (float(m) / kPiF) - 0.5, 0.0), float(m - 1u)), phi * (float(m) / kTwoPiF) - fraction);
}
bool slicePosition(PixelSetup p, vec3 w0, uint m, float fraction, out vec2 pos) {
  const vec3 t = turned(p, w0);
  if (t.y < p.skipBelowY) return false;
  if (dot(t, p.axis) > p.coreCos) return false;  // the lobe path's core
  pos = positionOf(t, m, fraction);
  return true;
}

// ρ_c at the object-frame direction w0, bilinear in the slice texels (core
// fused_kernel.cpp, the pass's lookup).
vec3 bilinearAt(const bool blended, PixelSetup p, vec2 pos) {
  const int mask = int(p.m) - 1;
  const float rowFloor = floor(pos.x), colFloor = floor(pos.y);
  const float tRow = pos.x - rowFloor, tCol = pos.y - colFloor;
  const uint r0 = uint(rowFloor);
  const uint r1 = min(r0 + 1u, p.m - 1u);
  const uint c0 = uint((int(colFloor) - p.shift) & mask);
  const uint c1 = (c0 + 1u) & uint(mask);
  const vec3 a = texel(blended, p, r0 * p.m + c0);
  const vec3 b = texel(blended, p, r0 * p.m + c1);
  const vec3 c = texel(blended, p, r1 * p.m + c0);
  const vec3 e = texel(blended, p, r1 * p.m + c1);
  const vec3 top = tCol * (b - a) + a;
  const vec3 bottom = tCol * (e - c) + c;
  return tRow * (bottom - top) + top;
}
vec3 rhoAt(const bool blended, PixelSetup p, vec3 w0) {
  vec2 pos;
  if (!slicePosition(p, w0, p.m, p.fraction, pos)) return vec3(0.0);
  return bilinearAt(blended, p, pos);
}

// ρ_c at the object-frame direction w0 for a point light: slicePosition at
// the point slices' level, then Catmull-Rom over 4 × 4 taps of the point
// slices (rows clamped, columns wrapped), each tap blended between the two
// slices (core point_rho_kernel.cpp; shared_layout.h catmullRomWeights).
vec3 pointRhoAt(PixelSetup p, vec3 w0) {
  vec2 pos;
  if (!slicePosition(p, w0, p.pointM, p.pointFraction, pos)) return vec3(0.0);
  const int mask = int(p.pointM) - 1;
  const float rowFloor = floor(pos.x), colFloor = floor(pos.y);
  const vec4 wr = catmullRomWeights(pos.x - rowFloor);
  const vec4 wc = catmullRomWeights(pos.y - colFloor);
  const int r0 = int(rowFloor);
  const int c0 = (int(colFloor) - p.pointShift) & mask;
  vec3 sum = vec3(0.0);
  for (int i = 0; i < 4; ++i) {
    const uint row = uint(clamp(r0 - 1 + i, 0, int(p.pointM) - 1));
    vec3 across = vec3(0.0);
    for (int j = 0; j < 4; ++j) {
      const uint k = row * p.pointM + uint((c0 - 1 + j) & mask);
      const vec3 a = texelFetch(pointTexels, int(p.pointBase0 + k)).rgb;
      const vec3 b = texelFetch(pointTexels, int(p.pointBase1 + k)).rgb;
      across += wc[j] * (a + p.weight * (b - a));
    }
    sum += wr[i] * across;
  }
  return max(sum, vec3(0.0));  // the cubic overshoots below zero beside a steep lobe
}

// Bit i of the visibility whose word 0 is `base`, as 0.0 or 1.0.
float bitOf(uint base, uint i) {
  return float((texelFetch(visibilityBits, int(base + i / 32u)).r >> (i & 31u)) & 1u);
}

// 1. Σ over the directions of this invocation (i ≡ lid mod LOCAL). Called
// with a constant `blended`, so each call is its own loop without the other
// kind of lookup (SIMD devices such as lavapipe would otherwise run both).
vec3 sumDirections(const bool blended, PixelSetup p, out vec3 norm) {
  vec3 acc = vec3(0.0);
  norm = vec3(0.0);
  for (uint i = p.firstRow * p.m + gl_LocalInvocationID.x; i < p.endRow * p.m; i += LOCAL) {
    const vec4 dir = texelFetch(directions, int(p.directionBase + i));  // xyz, and w = ΔΩ
    const vec3 rho = rhoAt(blended, p, dir.xyz);
    norm += dir.w * rho;
    // V = ((0 + b0·bit0) + b1·bit1) + b2·bit2, blendVisibility's order (the
    // products are exact, so a fused multiply-add changes nothing).
    const float vis = p.sh.b[0] * bitOf(p.bits0, i) + p.sh.b[1] * bitOf(p.bits1, i) + p.sh.b[2] * bitOf(p.bits2, i);
    const vec3 w = texelFetch(light, int(p.lightBase + i)).rgb * vis;
    acc += w * rho;
  }
  return acc;
}

#include "common/fused_cells.glsl"
#include "common/fused_smooth.glsl"
#include "common/prefiltered.glsl"

// The lobe path (shared_layout.h, core fused.cpp lobeShade): E_c of the
// core times Σ_i w_i·L(ω_i) over the lobe's samples, each read at its level.
vec3 lobeShade(ObjectInfo o, RotationSample rs, SliceBlend blend, uint seen) {
  if ((seen & kLobeSeenBit) == 0u) return vec3(0.0);
  // blendLobes read field by field and sample by sample in a loop kept
  // rolled: a SliceLobe copied whole (560 bytes, twice) and the loop
  // unrolled made lavapipe's compile of this pass take a minute (docs/gpu.md).
  const uint a = o.sliceBase + blend.first, b = o.sliceBase + blend.second;
  const float t = blend.weight;
  const float theta = lobes[a].energy.w + t * (lobes[b].energy.w - lobes[a].energy.w);
  const vec2 sc = sinCosPrecise(theta);
  const mat3 toLight = mat3(o.toLight[0].xyz, o.toLight[1].xyz, o.toLight[2].xyz) * rotationYXY(rs.alpha, rs.beta, rs.gamma);
  const vec3 axis = toLight * vec3(0.0, sc.y, -sc.x);
  const vec3 u = toLight * vec3(1.0, 0.0, 0.0);
  const vec3 v = toLight * vec3(0.0, -sc.x, -sc.y);
  vec3 sum = vec3(0.0);
  [[dont_unroll]] for (uint i = 0u; i < kLobeSamples; ++i) {
    const vec4 sa = lobes[a].samples[i];
    const vec4 s = sa + t * (lobes[b].samples[i] - sa);
    const vec2 x = sinCosPrecise(s.x), y = sinCosPrecise(s.y);
    sum += s.w * prefilteredAt(s.z, x.y * axis + x.x * (y.y * u + y.x * v));
  }
  const vec3 core = lobes[a].core.rgb + t * (lobes[b].core.rgb - lobes[a].core.rgb);
  return core * sum;
}

// sum + Σ_k bit_k·power_k·ρ(Rᵀd_k) over the lights the sample sees, added
// one by one in light order (fusedShade's order).
vec3 addPointLights(PixelSetup p, uint object, uint count, uint seen, vec3 sum) {
  for (uint k = 0u; k < count; ++k) {
    if (((seen >> k) & 1u) == 0u) continue;
    const PointLight l = pointLights[object * kMaxPointLights + k];
    sum += l.power.rgb * pointRhoAt(p, l.direction.xyz);
  }
  return sum;
}

// The pass's sum less the sky other objects hide from sample s, taken off
// as a light (fusedShade's `hidden`): the sum a pixel keeps for its
// children (FusedSum), so one that takes its parents' takes theirs less
// their hidden sky and reads none of its own.
vec3 lessHiddenSky(ObjectInfo o, uint s, vec3 energy, vec3 sum) {
  if ((o.flags & kObjectSkyHidden) != 0u) {
    const HiddenLight h = hidden[s];
    if (h.power.r > 0.0 || h.power.g > 0.0 || h.power.b > 0.0) sum -= h.power * energy / kPiF;
  }
  return sum;
}

// The radiance from the pixel's sum (the pass's with the lobe's energy put
// back and the hidden sky taken off, or its parents': FusedSum): the point
// lights and the lobe path added as fusedShade adds them, the whole kept ≥ 0
// before the lobe path.
vec3 finishSum(PixelSetup p, ObjectInfo o, RotationSample rs, SliceBlend blend, uint seen, vec3 sum, bool lobePath) {
  if ((seen & 0xFFFFu) != 0u) {
    sum = addPointLights(p, p.sh.object, o.pointLights, seen, sum);
  }
  sum = max(sum, vec3(0.0));
  if (lobePath) sum += lobeShade(o, rs, blend, seen);
  return sum;
}

// The ground: its map light is the same at every point (closed form on the
// host) less the share the objects hide (the word's upper half); the point
// lights' shadow bits vary. One invocation's work.
void shadeGround(ShadeSample sh, ObjectInfo o, uint seen) {
  atomicAdd(sliceCounts[kSliceCountsPerObject * sh.object], 1u);  // read no slice: counted so that every sample is
  vec3 sum = groundSkyKept(seen) * o.groundRadiance.rgb;
  for (uint k = 0u; k < o.pointLights; ++k) {
    if (((seen >> k) & 1u) != 0u) sum += pointLights[sh.object * kMaxPointLights + k].power.rgb;
  }
  radiance[sh.pixel] = vec4(sum, 1.0);
}

// How shadePixel takes sample s: the whole workgroup's, deciding and
// summing (kPixelWhole); one invocation's, shading it where it needs no
// sum of its own (the ground, a whole lobe path, a sum taken from its
// parents) and returning false where it does (kPixelDecide); the
// workgroup's, summing it, already decided (kPixelSum).
const uint kPixelWhole = 0u;
const uint kPixelDecide = 1u;
const uint kPixelSum = 2u;

// Returns false only where `how` is kPixelDecide and the sample sums its own.
bool shadePixel(uint s, uint how) {
  const uint lid = gl_LocalInvocationID.x;
  const bool alone = how == kPixelDecide;  // one invocation's: no workgroup-wide step before it returns
  const bool writer = alone || lid == 0u;
  const ShadeSample sh = shade[s];
  const ObjectInfo o = objects[sh.object];
  const uint seen = masks[s];

  if ((o.flags & kObjectGround) != 0u) {
    if (writer) shadeGround(sh, o, seen);
    return true;  // uniform over the workgroup: no barrier skipped by some invocations only
  }

  const RotationSample rs = samples[s];
  const SliceBlend blend = sliceBlendAt(rs.thetaOut, o.thetaSamples, INTERPOLATE);
  const bool blended = blend.weight != 0.0 && blend.second != blend.first;
  // Counted as shaded from one slice or two below, or as taken from its
  // neighbours (word 6), where it reads no slice of the pass.
  const uint sliceWord = kSliceCountsPerObject * sh.object + (blended ? 1u : 0u);

  // The lobe path (fused.h LobePath): all of the lobe, with no pass, or
  // its core, with the pass over the rest.
  const bool lobePath = (o.flags & kObjectLobePath) != 0u;
  if (lobePath && o.lobeCore.x <= -1.0) {
    if (writer) {
      atomicAdd(sliceCounts[sliceWord], 1u);
      radiance[sh.pixel] = vec4(lobeShade(o, rs, blend, seen), 1.0);
    }
    return true;  // uniform over the workgroup
  }
  PixelSetup p;
  p.sh = sh;
  p.m = 1u << o.level;
  const uint n = p.m * p.m;
  p.directionBase = o.directionBase;
  const uint words = visibilityWords(o.level);
  p.bits0 = o.visibilityBase + (sh.vertex[0] - o.vertexBase) * words;
  p.bits1 = o.visibilityBase + (sh.vertex[1] - o.vertexBase) * words;
  p.bits2 = o.visibilityBase + (sh.vertex[2] - o.vertexBase) * words;
  p.base0 = o.texelBase + blend.first * n;
  p.base1 = o.texelBase + blend.second * n;
  p.weight = blend.weight;
  p.lightBase = o.lightBase;
  const vec2 sa = sinCosPrecise(rs.alpha), sb = sinCosPrecise(rs.beta);
  p.sinA = sa.x;
  p.cosA = sa.y;
  p.sinB = sb.x;
  p.cosB = sb.y;
  const vec2 column = columnOffset(rs.gamma, p.m);
  p.shift = int(column.x);
  p.fraction = column.y;
  p.pointM = 1u << o.pointLevel;
  p.pointBase0 = o.pointTexelBase + blend.first * p.pointM * p.pointM;
  p.pointBase1 = o.pointTexelBase + blend.second * p.pointM * p.pointM;
  const vec2 pointColumn = columnOffset(rs.gamma, p.pointM);
  p.pointShift = int(pointColumn.x);
  p.pointFraction = pointColumn.y;
  p.skipBelowY = o.skipBelowY;
  p.axis = vec3(0.0, 1.0, 0.0);
  p.coreCos = 2.0;
  p.coreCellCos = 2.0;
  p.reachCut = cellReachCut(p.m, p.skipBelowY);
  p.tolerance = o.sumTolerance;
  p.detail0 = (o.sliceBase + blend.first) * kCellDetailStride;
  p.detail1 = (o.sliceBase + (blend.weight != 0.0 ? blend.second : blend.first)) * kCellDetailStride;
  vec3 energy;
  if (lobePath) {
    const SliceLobe a = lobes[o.sliceBase + blend.first], b = lobes[o.sliceBase + blend.second];
    const float theta = a.energy.w + blend.weight * (b.energy.w - a.energy.w);
    const vec2 st = sinCosPrecise(theta), sg = sinCosPrecise(rs.gamma);
    p.axis = vec3(-st.x * sg.x, st.y, -st.x * sg.y);
    p.coreCos = o.lobeCore.x;
    p.coreCellCos = cosPrecise(min(acosPrecise(o.lobeCore.x) + cellReach(p.m), kPiF));  // fused.cpp's cos(core + reach)
    const vec3 e = a.energy.rgb + blend.weight * (b.energy.rgb - a.energy.rgb);
    const vec3 c = a.core.rgb + blend.weight * (b.core.rgb - a.core.rgb);
    energy = max(e - c, vec3(0.0));
  } else {
    const vec3 e0 = sliceEnergy[o.sliceBase + blend.first].rgb, e1 = sliceEnergy[o.sliceBase + blend.second].rgb;
    energy = e0 + blend.weight * (e1 - e0);
  }

  // The smooth sum: this pixel's from its parents where they allow
  // (shared_smooth.h), uniform over the workgroup (every invocation reads
  // the same records); its own sum and mirror kept for its children.
  const bool visited = push.stage != kSmoothSumOff && smoothVisited(sh, o);
  const vec3 mirror = visited ? smoothMirror(rs.alpha, rs.beta, rs.gamma, rs.thetaOut) : vec3(0.0);
  vec3 given;
  if (visited && how != kPixelSum && smoothTaken(sh, o, mirror, given)) {
    if (writer) {
      atomicAdd(sliceCounts[kSliceCountsPerObject * sh.object + 6u], 1u);
      radiance[sh.pixel] = vec4(finishSum(p, o, rs, blend, seen, given, lobePath), 1.0);
      smoothData[2u * sh.pixel] = vec4(given, uintBitsToFloat(sh.object + 1u));
      smoothData[2u * sh.pixel + 1u] = vec4(mirror, 0.0);
    }
    return true;  // uniform over the workgroup
  }
  if (alone) return false;
  if (lid == 0u) atomicAdd(sliceCounts[sliceWord], 1u);

  // Only rows that can reach the slice's non-zero cap (shared_layout.h
  // passRows). The range is uniform over the workgroup, so every device
  // skips the rows outside it for real (the test in rhoAt only masks lanes
  // on SIMD devices).
  const uvec2 rows = passRows(p.m, p.cosB, p.skipBelowY);
  p.firstRow = rows.x;
  p.endRow = rows.y;
  // Two slices: each tap blends its two texels (ρ is linear in the slice),
  // with no pass over the slice first and no scratch.
  vec3 norm, acc;
  uint counted = 0u;
  const bool cells = o.sumTolerance > 0.0;
  if (cells) {
    acc = blended ? sumCells(true, p, norm, counted) : sumCells(false, p, norm, counted);
  } else {
    acc = blended ? sumDirections(true, p, norm) : sumDirections(false, p, norm);
    if (lid == 0u) {
      atomicAdd(sliceCounts[kSliceCountsPerObject * sh.object + 2u], rows.y - rows.x);
      atomicMax(sliceCounts[kSliceCountsPerObject * sh.object + 3u], (rows.y - rows.x) * p.m);
    }
  }

  // 2. Reduce in invocation order, put the lobe's energy back (fused.cpp
  // energyKept: ×∫ρ / Σ ΔΩ·ρ), then the point lights and the lobe path.
  vec3 sum = vec3(0.0), sampled = vec3(0.0);
  uint directionsSummed = 0u;
  if (SUBGROUP_REDUCE != 0u) {
    sum = subgroupAdd(acc);
    sampled = subgroupAdd(norm);
    directionsSummed = subgroupAdd(counted);
  } else {
    partial[lid] = acc;
    partialSum[lid] = norm;
    partialCount[lid] = counted;
    sync();
    if (lid == 0u) {
      for (uint k = 0u; k < LOCAL; ++k) sum += partial[k];
      for (uint k = 0u; k < LOCAL; ++k) sampled += partialSum[k];
      for (uint k = 0u; k < LOCAL; ++k) directionsSummed += partialCount[k];
    }
  }
  if (lid == 0u) {
    if (cells) {  // coarse and fine cells (shared_passes.h words 4, 5), directions: one and 16 each
      const uint coarse = directionsSummed & 0xFFFFu, fine = directionsSummed >> 16u;
      atomicAdd(sliceCounts[kSliceCountsPerObject * sh.object + 4u], coarse);
      atomicAdd(sliceCounts[kSliceCountsPerObject * sh.object + 5u], fine);
      atomicMax(sliceCounts[kSliceCountsPerObject * sh.object + 3u], coarse + kCellDirections * fine);
    }
    for (int c = 0; c < 3; ++c) {
      if (sampled[c] > 0.0) sum[c] *= energy[c] / sampled[c];
    }
    sum = lessHiddenSky(o, s, energy, sum);
    if (visited) {
      smoothData[2u * sh.pixel] = vec4(sum, uintBitsToFloat(sh.object + 1u));
      smoothData[2u * sh.pixel + 1u] = vec4(mirror, 0.0);
    }
    radiance[sh.pixel] = vec4(finishSum(p, o, rs, blend, seen, sum, lobePath), 1.0);
  }
  if (SUBGROUP_REDUCE == 0u) sync();  // `partial` is reused by the next sample
  return true;
}

#include "common/fused_stages.glsl"

void main() {
  if (push.stage == kSmoothSumList) {
    listStages();
    return;
  }
  if (push.stage == kSmoothSumOff) {
    const uint count = counter.covered;
    for (uint s = gl_WorkGroupID.x; s < count; s += gl_NumWorkGroups.x) shadePixel(s, kPixelWhole);
    return;
  }
  if (push.part == kSmoothPartDecide) {
    decideStage();
    return;
  }
  // A stage's own sums, a workgroup each.
  const uint count = stageLists[kSmoothSumCounts + push.stage];
  const uint first = push.ownLists + stageLists[kSmoothListOffsets + push.stage];
  for (uint i = gl_WorkGroupID.x; i < count; i += gl_NumWorkGroups.x) shadePixel(stageLists[first + i], kPixelSum);
}
