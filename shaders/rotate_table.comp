// table: the storage baseline (Ng et al. 2004) — a float port of the CPU
// table rotator (server/core/src/rotate_table.cpp), to which the tests
// compare it coefficient by coefficient: canonicalise the rotation, pick the
// nearest pre-rotated copy (0, β_k, γ_j), apply α as an exact φ-shift.
//
// One workgroup per (sample, channel), 256 invocations by default (specialization constant 2).
// Shared memory: one map, N floats (16 KiB at level 6; LEVEL must lie in
// [1, 6]). The copy is loaded into it and shifted (rotate_shift.glsl).
//
// Binding 2, per object at methodBase (rotation_data.h, RotationMethod::Table):
//   [0] the object's first global slice index  [1] Kβ  [2] Kγ  [3] 0
//   [4 + (((t·3 + c)·Kβ + k)·Kγ + j)·N …] slice t, channel c rotated by
//   (0, β_k, γ_j), β_k = kπ/(Kβ−1), γ_j = 2πj/Kγ: the CPU rotator's copies.
#version 450
#extension GL_GOOGLE_include_directive : require

#include "rotate_common.glsl"
#include "haarcast/core/shared_frame.h"

layout(local_size_x = kGpuLocalSize, local_size_x_id = kSpecLocalSize) in;  // the renderer picks the size per device

shared float buf[N];

#include "rotate_shift.glsl"

// std::lround: halves away from zero (GLSL's round() leaves them open).
int roundHalfAway(float x) { return int(sign(x) * floor(abs(x) + 0.5)); }

void main() {
  const uint local = gl_WorkGroupID.x;
  if (local >= pushed.count) return;  // uniform over the workgroup
  const uint channel = gl_WorkGroupID.y;
  const RotationSample rs = samples[pushed.first + local];
  const uint out0 = (local * 3u + channel) * N;
  const uint theta = rs.slice - methodData[rs.methodBase];
  const int elevations = int(methodData[rs.methodBase + 1u]);
  const int spins = int(methodData[rs.methodBase + 2u]);

  // eulerFromMatrix(rotationMatrix(r)) (core/rotation.cpp; eulerYXYOf,
  // core/shared_frame.h): every Euler triple of one rotation finds the same
  // copy; at the gimbal pole the whole turn goes to α.
  const vec3 euler = eulerYXYOf(rotationYXY(rs.alpha, rs.beta, rs.gamma));
  const float alpha = euler.x, beta = euler.y, gamma = euler.z;

  // The nearest copy: β_k by rounding, γ_j by rounding around the circle.
  const int k = clamp(roundHalfAway(beta / kPiF * float(elevations - 1)), 0, elevations - 1);
  // γ ∈ [−π, π], so the rounded index is ≥ −Kγ/2 − 1: adding 2Kγ keeps %'s
  // operands non-negative (GLSL leaves % of negatives undefined).
  const int j = (roundHalfAway(gamma / kTwoPiF * float(spins)) + 2 * spins) % spins;
  const uint copyIndex = ((theta * 3u + channel) * uint(elevations) + uint(k)) * uint(spins) + uint(j);
  const uint copy = rs.methodBase + 4u + copyIndex * N;

  for (uint q = gl_LocalInvocationIndex; q < N; q += gl_WorkGroupSize.x) buf[q] = uintBitsToFloat(methodData[copy + q]);
  memoryBarrierShared();
  barrier();
  shiftPhiToOutput(alpha, out0);
}
