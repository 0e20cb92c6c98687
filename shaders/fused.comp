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
//   1. (lists only) the hit triangle's three vertex visibility lists,
//      weighted by the barycentrics, are scattered into one dense coefficient
//      array (vertex by vertex, in the CPU's order, so V's coefficients are
//      the CPU's floats);
//   2. (lists only) V is synthesised (inverse Haar, haar.cpp's steps) into
//      pixel form;
//   3. the invocations stride over the directions: Rᵀω with R = Ry(α)Rx(β)Ry(γ)
//      (γ only offsets the source column), θ', φ' with the CPU kernel's
//      atan2, ρ bilinear in the slice texels exactly as bilinearTaps (θ
//      clamped, φ wrapped); with two θₒ slices each tap is blended,
//      a + w·(b − a), as fusedShade blends texels; accumulated with W_c = L_c·V;
//   4. the partial sums are reduced in invocation order; radiance[pixel] = Σ.
//
// With VERTEX_PLANES (the host's choice where every vertex's pixel form fits
// in memory), V is instead blended from the vertices' pixel forms in step 3
// and steps 1–2 and their barriers disappear.
//
// The large read-only arrays of step 3 (slice texels, light, directions,
// vertex planes) are uniform texel buffers read with texelFetch: on a CPU
// device (lavapipe) a fetch is one vector gather, where a storage-buffer
// read at a per-invocation index goes lane by lane and component by
// component, each behind a branch (docs/gpu.md, "fused on lavapipe").
//
// Scratch per workgroup (lists only): N coefficients, the finest synthesis
// step's N values and the previous step's N/4 (steps alternate between the
// two), in shared memory when SHARED_FLOATS holds them (the host checks
// maxComputeSharedMemorySize), else in this group's slice of `scratch`.
#extension GL_GOOGLE_include_directive : require
#include "haarcast/core/shared_layout.h"
#include "common/frame.glsl"
#include "common/sphere.glsl"

layout(local_size_x_id = 2) in;
layout(constant_id = 0) const uint LEVEL = 5u;
layout(constant_id = 3) const uint SHARED_FLOATS = 1u;  // 1: the scratch lives in the `scratch` buffer
layout(constant_id = 4) const uint INTERPOLATE = 1u;    // RenderOptions::interpolateSlices
// 1: binding 10 holds every vertex's visibility in pixel form (N floats per
// vertex, synthesised once at prepare), and V(ω) = Σ_v b_v·V_v(ω) is formed
// in the direction loop: no merge, no synthesis, no scratch, no barrier but
// the reduction's. 0: binding 5 holds the sparse lists (steps 1–2).
layout(constant_id = 5) const uint VERTEX_PLANES = 0u;

const uint LOCAL = gl_WorkGroupSize.x;
const uint M = 1u << LEVEL;
const uint N = M * M;
// Scratch layout (lists only): [0, N) coefficients, [N, 2N) FINE, [2N, 2.25N) COARSE.
const uint FINE = N;            // where the synthesis step n = M writes (V in pixel form, row stride M)
const uint COARSE = 2u * N;     // where the step before it writes
const uint SCRATCH = VERTEX_PLANES != 0u ? 0u : 2u * N + N / 4u;

layout(std430, set = 0, binding = 0) readonly buffer Samples { RotationSample samples[]; };
layout(std430, set = 0, binding = 1) readonly buffer Shade { ShadeSample shade[]; };
layout(std430, set = 0, binding = 2) readonly buffer Objects { ObjectInfo objects[]; };
layout(set = 0, binding = 3) uniform samplerBuffer texels;       // slice s, direction k at s·N + k: RGB0
layout(set = 0, binding = 4) uniform samplerBuffer light;        // object o, direction k at o·N + k: (L·ΔΩ) RGB, 0
// Per vertex (first, count), then (index, value bits) pairs (VERTEX_PLANES = 0).
layout(std430, set = 0, binding = 5) readonly buffer VisibilityLists { uint visibilityLists[]; };
layout(set = 0, binding = 6) uniform samplerBuffer directions;   // pixel-centre unit vectors (xyz)
layout(std430, set = 0, binding = 7) coherent buffer Scratch { float scratch[]; };
layout(std430, set = 0, binding = 8) buffer Radiance { vec4 radiance[]; };
layout(std430, set = 0, binding = 9) readonly buffer Counter { CoverageCounter counter; };
layout(set = 0, binding = 10) uniform samplerBuffer visibilityPlanes;  // vertex v, direction k at v·N + k (VERTEX_PLANES = 1)

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

// What the direction loop needs of a pixel.
struct PixelSetup {
  ShadeSample sh;
  uint base0, base1;       // the two slices' texel 0 (equal without a blend)
  float weight;            // of the second slice
  uint lightBase;          // the object's light texel 0
  float sinA, cosA, sinB, cosB;
  int shift;               // whole source columns of γ
  float fraction;          // and the fraction
  float skipBelowY;
  uint firstRow, endRow;   // the rows that can reach the slice's non-zero cap
};

// Texel `index` of ρ: the slice's own, or the blend of the two slices.
vec3 texel(const bool blended, PixelSetup p, uint index) {
  const vec3 a = texelFetch(texels, int(p.base0 + index)).rgb;
  if (!blended) return a;
  const vec3 b = texelFetch(texels, int(p.base1 + index)).rgb;
  return a + p.weight * (b - a);
}

// 3. Σ over the directions of this invocation (i ≡ lid mod LOCAL). Called
// with a constant `blended`, so each call is its own loop without the other
// kind of lookup (SIMD devices such as lavapipe would otherwise run both).
vec3 sumDirections(const bool blended, PixelSetup p) {
  const float rowScale = float(M) / kPi, colScale = float(M) / kTwoPi;
  const int mask = int(M) - 1;
  vec3 acc = vec3(0.0);
  for (uint i = p.firstRow * M + gl_LocalInvocationID.x; i < p.endRow * M; i += LOCAL) {
    const vec3 w0 = texelFetch(directions, int(i)).xyz;
    const float x1 = p.cosA * w0.x - p.sinA * w0.z;  // R_y(−α)
    const float z1 = p.sinA * w0.x + p.cosA * w0.z;
    const float y2 = p.cosB * w0.y + p.sinB * z1;    // R_x(−β)
    if (y2 < p.skipBelowY) continue;  // reads only zero texels
    const float z2 = p.cosB * z1 - p.sinB * w0.y;
    const float theta = atan2Fast(sqrt(x1 * x1 + z2 * z2), y2);
    const float phi = atan2Fast(x1, z2);
    const float rowPos = min(max(theta * rowScale - 0.5, 0.0), float(M - 1u));
    const float colPos = phi * colScale - p.fraction;
    const float rowFloor = floor(rowPos), colFloor = floor(colPos);
    const float tRow = rowPos - rowFloor, tCol = colPos - colFloor;
    const uint r0 = uint(rowFloor);
    const uint r1 = min(r0 + 1u, M - 1u);
    const uint c0 = uint((int(colFloor) - p.shift) & mask);
    const uint c1 = (c0 + 1u) & uint(mask);
    const vec3 a = texel(blended, p, r0 * M + c0);
    const vec3 b = texel(blended, p, r0 * M + c1);
    const vec3 c = texel(blended, p, r1 * M + c0);
    const vec3 e = texel(blended, p, r1 * M + c1);
    const vec3 top = tCol * (b - a) + a;
    const vec3 bottom = tCol * (e - c) + c;
    const vec3 rho = tRow * (bottom - top) + top;
    const float vis = VERTEX_PLANES != 0u
                          ? p.sh.b[0] * texelFetch(visibilityPlanes, int(p.sh.vertex[0] * N + i)).r +
                                p.sh.b[1] * texelFetch(visibilityPlanes, int(p.sh.vertex[1] * N + i)).r +
                                p.sh.b[2] * texelFetch(visibilityPlanes, int(p.sh.vertex[2] * N + i)).r
                          : scratchGet(FINE + i);
    const vec3 w = texelFetch(light, int(p.lightBase + i)).rgb * vis;
    acc += w * rho;
  }
  return acc;
}

// Steps 1–2: V in pixel form at FINE in the scratch.
void synthesizeVisibility(ShadeSample sh) {
  const uint lid = gl_LocalInvocationID.x;
  // 1. V's coefficients: Σ_v b_v·V_v, vertex by vertex (indices are unique within a list).
  for (uint i = lid; i < N; i += LOCAL) scratchSet(i, 0.0);
  sync();
  for (uint v = 0u; v < 3u; ++v) {
    const uint first = visibilityLists[2u * sh.vertex[v]], count = visibilityLists[2u * sh.vertex[v] + 1u];
    for (uint e = lid; e < count; e += LOCAL) {
      const uint index = visibilityLists[2u * (first + e)];
      scratchSet(index, scratchGet(index) + sh.b[v] * uintBitsToFloat(visibilityLists[2u * (first + e) + 1u]));
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
}

void shadePixel(uint s) {
  const uint lid = gl_LocalInvocationID.x;
  RotationSample rs = samples[s];
  ShadeSample sh = shade[s];
  ObjectInfo o = objects[sh.object];

  if (VERTEX_PLANES == 0u) synthesizeVisibility(sh);

  // 3. The pass over the directions.
  const SliceBlend blend = sliceBlendAt(rs.thetaOut, o.thetaSamples, INTERPOLATE);
  PixelSetup p;
  p.sh = sh;
  p.base0 = (o.sliceBase + blend.first) * N;
  p.base1 = (o.sliceBase + blend.second) * N;
  p.weight = blend.weight;
  p.lightBase = sh.object * N;
  const vec2 sa = sinCosPrecise(rs.alpha), sb = sinCosPrecise(rs.beta);
  p.sinA = sa.x;
  p.cosA = sa.y;
  p.sinB = sb.x;
  p.cosB = sb.y;
  // Source column = φ'·M/2π − (γ·M/2π + ½): the offset's whole part shifts
  // the integer column, its fraction the float coordinate.
  float offset = rs.gamma * (float(M) / kTwoPi) + 0.5;
  offset -= floor(offset / float(M)) * float(M);
  const float whole = floor(offset);
  p.shift = int(whole);
  p.fraction = offset - whole;
  p.skipBelowY = o.skipBelowY;

  // Only rows that can reach the slice's non-zero cap: y2 = ω·a with
  // a = (sin β sin α, cos β, sin β cos α) at angle β from +Y, so y2 ≥
  // skipBelowY needs ω within δ = acos(skipBelowY) of a, and a pixel centre
  // at θᵢ is at least |θᵢ − β| from it. The margin covers float rounding.
  // The range is uniform over the workgroup, so every device skips the rows
  // outside it for real (the test in the loop only masks lanes on SIMD devices).
  p.firstRow = 0u;
  p.endRow = M;
  if (p.skipBelowY > -1.0) {
    const float rowScale = float(M) / kPi;
    const float axis = acosPrecise(clamp(p.cosB, -1.0, 1.0));
    const float reach = acosPrecise(min(p.skipBelowY, 1.0)) + 2e-3;
    p.firstRow = uint(clamp(floor((axis - reach) * rowScale - 0.5), 0.0, float(M)));
    p.endRow = uint(clamp(ceil((axis + reach) * rowScale - 0.5) + 1.0, 0.0, float(M)));
  }

  // Two slices: each tap blends its two texels (ρ is linear in the slice),
  // with no pass over the slice first and no scratch.
  vec3 acc;
  if (blend.weight != 0.0 && blend.second != blend.first) {
    acc = sumDirections(true, p);
  } else {
    acc = sumDirections(false, p);
  }

  // 4. Reduce in invocation order.
  partial[lid] = acc;
  sync();
  if (lid == 0u) {
    vec3 sum = vec3(0.0);
    for (uint k = 0u; k < LOCAL; ++k) sum += partial[k];
    radiance[sh.pixel] = vec4(sum, 1.0);
  }
  sync();  // `partial` and the scratch are reused by the next pixel
}

void main() {
  scratchBase = gl_WorkGroupID.x * SCRATCH;
  const uint count = counter.covered;
  for (uint s = gl_WorkGroupID.x; s < count; s += gl_NumWorkGroups.x) shadePixel(s);
}
