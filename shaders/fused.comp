#version 450
// The "fused" pass (core/fused.h, fused_kernel.cpp): per covered pixel,
//   I_c = Σ_ω W_c(ω)·ρ_c(Rᵀω),   W_c = (L_c·ΔΩ)(ω)·V(ω),
// the rotation and the triple product in one sum over the M² map directions,
// equal by Parseval to `spatial` followed by the Haar triple product.
//
// One workgroup per covered pixel at a time; workgroups loop over the
// compacted pixels (s = group, group + groups, …), so the dispatch is sized
// by the rotation-input pass's indirect arguments and a bounded scratch
// serves any number of pixels. Per pixel:
//   1. the hit triangle's three vertex visibility lists, weighted by the
//      barycentrics, are scattered into one dense coefficient array (vertex by
//      vertex, in the CPU's order, so V's coefficients are the CPU's floats);
//   2. V is synthesised (inverse Haar, haar.cpp's steps) into pixel form;
//   3. the invocations stride over the directions: Rᵀω with R = Ry(α)Rx(β)Ry(γ)
//      (γ only offsets the source column), θ', φ' with the precise atan2,
//      ρ bilinear in the θₒ-blended slice texels exactly as bilinearTaps (θ
//      clamped, φ wrapped), accumulated with W_c = L_c·V;
//   4. the partial sums are reduced in invocation order; radiance[pixel] = Σ.
//
// Scratch per workgroup: N coefficients, the finest synthesis step's N
// values and the previous step's N/4 (steps alternate between the two), in
// shared memory when SHARED_FLOATS holds them (the host checks
// maxComputeSharedMemorySize), else in this group's slice of `scratch`.
#extension GL_GOOGLE_include_directive : require
#include "haarcast/core/shared_layout.h"
#include "common/frame.glsl"
#include "common/sphere.glsl"

layout(local_size_x_id = 2) in;
layout(constant_id = 0) const uint LEVEL = 5u;
layout(constant_id = 3) const uint SHARED_FLOATS = 1u;  // 1: the scratch lives in the `scratch` buffer
layout(constant_id = 4) const uint INTERPOLATE = 1u;    // RenderOptions::interpolateSlices

const uint LOCAL = gl_WorkGroupSize.x;
const uint M = 1u << LEVEL;
const uint N = M * M;
const uint SCRATCH = N + N + N / 4u;
const uint FINE = N;            // where the synthesis step n = M writes (V in pixel form, row stride M)
const uint COARSE = 2u * N;     // where the step before it writes

layout(std430, set = 0, binding = 0) readonly buffer Samples { RotationSample samples[]; };
layout(std430, set = 0, binding = 1) readonly buffer Shade { ShadeSample shade[]; };
layout(std430, set = 0, binding = 2) readonly buffer Objects { ObjectInfo objects[]; };
layout(std430, set = 0, binding = 3) readonly buffer Texels { vec4 texels[]; };      // slice s at s·N, RGB0
layout(std430, set = 0, binding = 4) readonly buffer Light { float light[]; };       // object o, channel c at (3o + c)·N
layout(std430, set = 0, binding = 5) readonly buffer Visibility { uvec2 visibility[]; };  // per vertex (first, count), then (index, value bits)
layout(std430, set = 0, binding = 6) readonly buffer Directions { vec4 directions[]; };   // pixel-centre unit vectors
layout(std430, set = 0, binding = 7) coherent buffer Scratch { float scratch[]; };
layout(std430, set = 0, binding = 8) buffer Radiance { vec4 radiance[]; };
layout(std430, set = 0, binding = 9) readonly buffer Counter { CoverageCounter counter; };

shared float sharedScratch[SHARED_FLOATS];
shared vec3 partial[LOCAL];

uint scratchBase;

float scratchGet(uint i) { return SHARED_FLOATS > 1u ? sharedScratch[i] : scratch[scratchBase + i]; }
void scratchSet(uint i, float v) {
  if (SHARED_FLOATS > 1u) {
    sharedScratch[i] = v;
  } else {
    scratch[scratchBase + i] = v;
  }
}
void sync() {
  memoryBarrierShared();
  memoryBarrierBuffer();
  barrier();
}

// Texel `index` of the blended slice: a + w·(b − a), as fusedShade blends.
vec3 texel(uint base0, uint base1, float w, bool two, uint index) {
  vec3 a = texels[base0 + index].rgb;
  if (!two) return a;
  vec3 b = texels[base1 + index].rgb;
  return a + w * (b - a);
}

void shadePixel(uint s) {
  const uint lid = gl_LocalInvocationID.x;
  RotationSample rs = samples[s];
  ShadeSample sh = shade[s];
  ObjectInfo o = objects[sh.object];

  // 1. V's coefficients: Σ_v b_v·V_v, vertex by vertex (indices are unique within a list).
  for (uint i = lid; i < N; i += LOCAL) scratchSet(i, 0.0);
  sync();
  uint vertex[3] = sh.vertex;
  float weight[3] = sh.b;
  for (uint v = 0u; v < 3u; ++v) {
    uvec2 header = visibility[vertex[v]];
    for (uint e = lid; e < header.y; e += LOCAL) {
      uvec2 entry = visibility[header.x + e];
      scratchSet(entry.x, scratchGet(entry.x) + weight[v] * uintBitsToFloat(entry.y));
    }
    sync();
  }

  // 2. Inverse Haar: step n turns the top-left n×n block (s from the previous
  // step's output, h, v, d from the coefficients) into n×n values; the last
  // step (n = M) writes FINE, the one before COARSE, and so on alternately.
  for (uint n = 2u, step = 1u; n <= M; n *= 2u, ++step) {
    const uint half_ = n / 2u;
    const uint dst = ((LEVEL - step) & 1u) == 0u ? FINE : COARSE;
    const uint src = ((LEVEL - step) & 1u) == 0u ? COARSE : FINE;
    for (uint b = lid; b < half_ * half_; b += LOCAL) {
      const uint i = b / half_, j = b % half_;
      const float sc = n == 2u ? scratchGet(0u) : scratchGet(src + i * half_ + j);
      const float h = scratchGet(i * M + j + half_);
      const float vv = scratchGet((i + half_) * M + j);
      const float d = scratchGet((i + half_) * M + j + half_);
      const uint out0 = dst + (2u * i) * n + 2u * j;
      scratchSet(out0, 0.5 * (sc + h + vv + d));
      scratchSet(out0 + 1u, 0.5 * (sc - h + vv - d));
      scratchSet(out0 + n, 0.5 * (sc + h - vv - d));
      scratchSet(out0 + n + 1u, 0.5 * (sc - h - vv + d));
    }
    sync();
  }

  // 3. The pass over the directions.
  const SliceBlend blend = sliceBlendAt(rs.thetaOut, o.thetaSamples, INTERPOLATE);
  const uint base0 = (o.sliceBase + blend.first) * N, base1 = (o.sliceBase + blend.second) * N;
  const bool two = blend.weight != 0.0 && blend.second != blend.first;
  const vec2 sa = sinCosPrecise(rs.alpha), sb = sinCosPrecise(rs.beta);
  const float sinA = sa.x, cosA = sa.y, sinB = sb.x, cosB = sb.y;
  // Source column = φ'·M/2π − (γ·M/2π + ½): the offset's whole part shifts
  // the integer column, its fraction the float coordinate.
  float offset = rs.gamma * (float(M) / kTwoPi) + 0.5;
  offset -= floor(offset / float(M)) * float(M);
  const float whole = floor(offset);
  const int shift = int(whole);
  const float fraction = offset - whole;
  const float skipBelowY = o.skipBelowY;
  const float rowScale = float(M) / kPi, colScale = float(M) / kTwoPi;
  const uint lightBase = 3u * sh.object * N;
  const int mask = int(M) - 1;

  // Only rows that can reach the slice's non-zero cap: y2 = ω·a with
  // a = (sin β sin α, cos β, sin β cos α) at angle β from +Y, so y2 ≥
  // skipBelowY needs ω within δ = acos(skipBelowY) of a, and a pixel centre
  // at θᵢ is at least |θᵢ − β| from it. The margin covers float rounding.
  // The range is uniform over the workgroup, so every device skips the rows
  // outside it for real (the test below only masks lanes).
  uint firstRow = 0u, endRow = M;
  if (skipBelowY > -1.0) {
    const float axis = acosPrecise(clamp(cosB, -1.0, 1.0));
    const float reach = acosPrecise(min(skipBelowY, 1.0)) + 2e-3;
    firstRow = uint(clamp(floor((axis - reach) * rowScale - 0.5), 0.0, float(M)));
    endRow = uint(clamp(ceil((axis + reach) * rowScale - 0.5) + 1.0, 0.0, float(M)));
  }

  vec3 acc = vec3(0.0);
  for (uint i = firstRow * M + lid; i < endRow * M; i += LOCAL) {
    const vec3 w0 = directions[i].xyz;
    const float x1 = cosA * w0.x - sinA * w0.z;  // R_y(−α)
    const float z1 = sinA * w0.x + cosA * w0.z;
    const float y2 = cosB * w0.y + sinB * z1;    // R_x(−β)
    if (y2 < skipBelowY) continue;  // reads only zero texels
    const float z2 = cosB * z1 - sinB * w0.y;
    const float theta = atan2Precise(sqrt(x1 * x1 + z2 * z2), y2);
    const float phi = atan2Precise(x1, z2);
    const float rowPos = min(max(theta * rowScale - 0.5, 0.0), float(M - 1u));
    const float colPos = phi * colScale - fraction;
    const float rowFloor = floor(rowPos), colFloor = floor(colPos);
    const float tRow = rowPos - rowFloor, tCol = colPos - colFloor;
    const uint r0 = uint(rowFloor);
    const uint r1 = min(r0 + 1u, M - 1u);
    const uint c0 = uint((int(colFloor) - shift) & mask);
    const uint c1 = (c0 + 1u) & uint(mask);
    const vec3 a = texel(base0, base1, blend.weight, two, r0 * M + c0);
    const vec3 b = texel(base0, base1, blend.weight, two, r0 * M + c1);
    const vec3 c = texel(base0, base1, blend.weight, two, r1 * M + c0);
    const vec3 e = texel(base0, base1, blend.weight, two, r1 * M + c1);
    const vec3 top = tCol * (b - a) + a;
    const vec3 bottom = tCol * (e - c) + c;
    const vec3 rho = tRow * (bottom - top) + top;
    const float vis = scratchGet(FINE + i);
    const vec3 w = vec3(light[lightBase + i], light[lightBase + N + i], light[lightBase + 2u * N + i]) * vis;
    acc += w * rho;
  }

  // 4. Reduce in invocation order.
  partial[lid] = acc;
  sync();
  if (lid == 0u) {
    vec3 sum = vec3(0.0);
    for (uint k = 0u; k < LOCAL; ++k) sum += partial[k];
    radiance[sh.pixel] = vec4(sum, 1.0);
  }
  sync();  // the scratch and `partial` are reused by the next pixel
}

void main() {
  scratchBase = gl_WorkGroupID.x * SCRATCH;
  const uint count = counter.covered;
  for (uint s = gl_WorkGroupID.x; s < count; s += gl_NumWorkGroups.x) shadePixel(s);
}
