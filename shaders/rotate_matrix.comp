// matrix: the rotation-matrix baseline (Wang et al. 2006) — a float port of
// the CPU matrix rotator (server/core/src/rotate_matrix.cpp), to which the
// tests compare it coefficient by coefficient: g = shift_α(blend of the two
// nearest elevation matrices applied to shift_γ(f)).
//
// One workgroup per (sample, channel), 256 invocations by default (specialization constant 2).
// Shared memory: one map, N floats (16 KiB at level 6; LEVEL must lie in
// [1, 6]). shift_γ(f) goes to the output region, the sparse products to
// shared memory, and shift_α of them back to the output (rotate_shift.glsl).
//
// Binding 2, per object at methodBase (rotation_data.h, RotationMethod::Matrix):
//   [0] K  [1..3] 0  [4 + k] offset of matrix k from methodBase;
//   matrix k (elevate_{β_k}, β_k = kπ/(K−1), Haar → Haar, compressed rows):
//   rowStart[N + 1], then entries as (column, value bits) pairs.
//   The matrices depend on the level only: every slice and channel shares them.
#version 450
#extension GL_GOOGLE_include_directive : require

#include "rotate_common.glsl"

layout(local_size_x = kGpuLocalSize, local_size_x_id = kSpecLocalSize) in;  // the renderer picks the size per device

shared float buf[N];

#include "rotate_shift.glsl"

// Row `row` of matrix at `base` (absolute word offset) times the map in the
// output region.
float rowTimesShifted(uint base, uint row, uint out0) {
  const uint begin = methodData[base + row], end = methodData[base + row + 1u];
  const uint entries = base + N + 1u;
  float sum = 0.0;
  for (uint e = begin; e < end; ++e)
    sum += uintBitsToFloat(methodData[entries + 2u * e + 1u]) * rotated[out0 + methodData[entries + 2u * e]];
  return sum;
}

void main() {
  const uint local = gl_WorkGroupID.x;
  if (local >= pushed.count) return;  // uniform over the workgroup
  const uint channel = gl_WorkGroupID.y;
  const RotationSample rs = samples[pushed.first + local];
  const uint out0 = (local * 3u + channel) * N;
  const uint matrices = methodData[rs.methodBase];

  // β into [0, π]: R_x(−b) = R_y(π) R_x(b) R_y(−π), so (α, −b, γ) is
  // (α + π, b, γ − π). β − 2π·round(β/2π) is std::remainder (halves to even
  // aside, which only swaps ±π, both of which then land on π).
  float alpha = rs.alpha, beta = rs.beta - kTwoPiF * roundEven(rs.beta / kTwoPiF), gamma = rs.gamma;
  if (beta < 0.0) {
    alpha += kPiF;
    gamma -= kPiF;
    beta = -beta;
  }
  // The neighbouring samples k, k+1 and the blend t; a β on a sample (up to
  // rounding) uses that matrix alone.
  const uint last = matrices - 1u;
  const float u = beta / kPiF * float(last);
  const float nearest = round(u);
  uint k;
  float t;
  if (abs(u - nearest) < 1e-9) {
    k = uint(nearest);
    t = 0.0;
  } else {
    k = min(uint(floor(u)), last - 1u);
    t = u - float(k);
  }
  const uint lower = rs.methodBase + methodData[rs.methodBase + 4u + k];
  const uint upper = t == 0.0 ? lower : rs.methodBase + methodData[rs.methodBase + 5u + k];

  // shift_γ(f) → output region.
  const uint slice = (rs.slice * 3u + channel) * N;
  for (uint q = gl_LocalInvocationIndex; q < N; q += gl_WorkGroupSize.x) buf[q] = slices[slice + q];
  memoryBarrierShared();
  barrier();
  shiftPhiToOutput(gamma, out0);

  // The blended sparse products → shared memory.
  for (uint row = gl_LocalInvocationIndex; row < N; row += gl_WorkGroupSize.x) {
    const float a = rowTimesShifted(lower, row, out0);
    buf[row] = t == 0.0 ? a : (1.0 - t) * a + t * rowTimesShifted(upper, row, out0);
  }
  memoryBarrierBuffer();
  memoryBarrierShared();
  barrier();

  // shift_α of them → output region.
  shiftPhiToOutput(alpha, out0);
}
