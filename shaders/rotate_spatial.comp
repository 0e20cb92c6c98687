#version 450
// `spatial` rotation of BRDF slices (core rotate_spatial.cpp), one workgroup
// per (sample, channel): inverse Haar → bilinear resample at Rᵀω of every
// pixel centre → forward Haar. The rotation contract (docs/gpu.md,
// "Rotation shaders") fixes the bindings, push constants and layouts.
//
// Local size: specialization constant 2 (default 256; the renderer picks
// fewer on CPU devices, where a barrier switches between every SIMD group of
// the workgroup). Shared memory: one map of N = 4^LEVEL floats (16 KiB at
// level 6). The resampled map g is staged in this sample's own output region
// while f still occupies shared memory, then read back for the analysis.
#extension GL_GOOGLE_include_directive : require
#include "common/sphere.glsl"
#include "haarcast/core/shared_layout.h"  // RotationSample

layout(local_size_x_id = kSpecLocalSize) in;
layout(constant_id = kSpecLevel) const int LEVEL = 5;
layout(constant_id = kSpecThetaSamples) const int THETA_SAMPLES = 16;  // part of the contract; unused here

const int LOCAL = int(gl_WorkGroupSize.x);
const int M = 1 << LEVEL;
const int N = M * M;

layout(push_constant) uniform Push { RotationPush pc; };

layout(std430, set = 0, binding = kRotateSamplesBinding) readonly buffer Samples { RotationSample samples[]; };
layout(std430, set = 0, binding = kRotateSlicesBinding) readonly buffer Slices { float slices[]; };
layout(std430, set = 0, binding = kRotateMethodDataBinding) readonly buffer MethodData { uint methodData[]; };
layout(std430, set = 0, binding = kRotateRotatedBinding) coherent buffer Rotated { float rotated[]; };

shared float map[N];

// One synthesis step of haar.cpp on the top-left n×n block of `map` (row
// stride M): each thread reads whole 2×2 groups into registers, then all
// write, so the in-place update never reads a value already overwritten.
// At most N/4/LOCAL groups per thread (4 at level 6 with 256 threads).
const int kMaxGroups = (N / 4 + LOCAL - 1) / LOCAL;

void synthesisStep(int n) {
  int half_ = n / 2;
  int groups = half_ * half_;
  vec4 v[kMaxGroups];
  for (int k = 0; k < kMaxGroups; ++k) {
    int g = int(gl_LocalInvocationID.x) + LOCAL * k;
    if (g >= groups) break;
    int i = g / half_, j = g % half_;
    float s = map[i * M + j], h = map[i * M + j + half_];
    float vv = map[(i + half_) * M + j], d = map[(i + half_) * M + j + half_];
    v[k] = 0.5 * vec4(s + h + vv + d, s - h + vv - d, s + h - vv - d, s - h - vv + d);
  }
  barrier();
  for (int k = 0; k < kMaxGroups; ++k) {
    int g = int(gl_LocalInvocationID.x) + LOCAL * k;
    if (g >= groups) break;
    int i = g / half_, j = g % half_;
    map[(2 * i) * M + 2 * j] = v[k].x;
    map[(2 * i) * M + 2 * j + 1] = v[k].y;
    map[(2 * i + 1) * M + 2 * j] = v[k].z;
    map[(2 * i + 1) * M + 2 * j + 1] = v[k].w;
  }
  barrier();
}

// One analysis step: the 2×2 groups of the top-left n×n block become s, h,
// v, d in its quadrants (haar.h layout).
void analysisStep(int n) {
  int half_ = n / 2;
  int groups = half_ * half_;
  vec4 v[kMaxGroups];
  for (int k = 0; k < kMaxGroups; ++k) {
    int g = int(gl_LocalInvocationID.x) + LOCAL * k;
    if (g >= groups) break;
    int i = g / half_, j = g % half_;
    float p = map[(2 * i) * M + 2 * j], q = map[(2 * i) * M + 2 * j + 1];
    float r = map[(2 * i + 1) * M + 2 * j], t = map[(2 * i + 1) * M + 2 * j + 1];
    v[k] = 0.5 * vec4(p + q + r + t, p - q + r - t, p + q - r - t, p - q - r + t);
  }
  barrier();
  for (int k = 0; k < kMaxGroups; ++k) {
    int g = int(gl_LocalInvocationID.x) + LOCAL * k;
    if (g >= groups) break;
    int i = g / half_, j = g % half_;
    map[i * M + j] = v[k].x;
    map[i * M + j + half_] = v[k].y;
    map[(i + half_) * M + j] = v[k].z;
    map[(i + half_) * M + j + half_] = v[k].w;
  }
  barrier();
}

void main() {
  uint local = gl_WorkGroupID.x;
  if (local >= pc.count) return;  // uniform per workgroup: safe before barriers
  uint c = gl_WorkGroupID.y;
  RotationSample s = samples[pc.first + local];
  uint src = (s.slice * 3u + c) * uint(N);
  uint dst = (local * 3u + c) * uint(N);
  uint tid = gl_LocalInvocationID.x;

  for (uint k = tid; k < uint(N); k += uint(LOCAL)) map[k] = slices[src + k];
  barrier();
  for (int n = 2; n <= M; n *= 2) synthesisStep(n);

  // g(ω) = f(Rᵀω) at every pixel centre (rotate_spatial.cpp).
  mat3 rt = transpose(rotationYXY(s.alpha, s.beta, s.gamma));
  for (uint k = tid; k < uint(N); k += uint(LOCAL)) {
    int i = int(k) / M, j = int(k) % M;
    vec2 tp = directionToSpherical(rt * sphericalToDirection((float(i) + 0.5) * kPiF / float(M),
                                                             (float(j) + 0.5) * kTwoPiF / float(M)));
    Taps t = bilinearTaps(LEVEL, tp.x, tp.y);
    float top = (1.0 - t.t.y) * map[t.rc.x * M + t.rc.z] + t.t.y * map[t.rc.x * M + t.rc.w];
    float bottom = (1.0 - t.t.y) * map[t.rc.y * M + t.rc.z] + t.t.y * map[t.rc.y * M + t.rc.w];
    rotated[dst + k] = (1.0 - t.t.x) * top + t.t.x * bottom;
  }
  // Every thread's g values visible to the whole workgroup before f is replaced.
  memoryBarrierBuffer();
  barrier();
  for (uint k = tid; k < uint(N); k += uint(LOCAL)) map[k] = rotated[dst + k];
  barrier();
  for (int n = M; n >= 2; n /= 2) analysisStep(n);
  for (uint k = tid; k < uint(N); k += uint(LOCAL)) rotated[dst + k] = map[k];
}
