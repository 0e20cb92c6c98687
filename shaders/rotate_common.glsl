// Shared by the rotation shaders rotate_haar/table/matrix.comp: the rotation
// shader contract (bindings, push constants, specialisation constants) and the
// small pieces of core math they all need, each a float port of the CPU
// function it names. Included with GL_GOOGLE_include_directive; not compiled
// on its own.
//
// Contract (shared with rotate_spatial.comp and the host dispatch):
//   constant_id kSpecLevel = LEVEL: the map is M×M, M = 2^LEVEL, N = M² coefficients in
//     the CPU HaarMap quadrant layout (haarcast/core/haar.h).
//   constant_id kSpecThetaSamples = THETA_SAMPLES: slices per channel per object.
//   push constants (RotationPush): rotate samples first … first+count−1.
//   bindings (core/shared_passes.h): kRotateSamplesBinding, RotationSample
//   per sample; kRotateSlicesBinding, unrotated slices, slice s channel c at
//   (s·3 + c)·N; kRotateMethodDataBinding, per-method data (rotation_data.h);
//   kRotateRotatedBinding, output, local sample i channel c at (i·3 + c)·N.
//   Dispatch (count, 3, 1): one workgroup per (sample, channel).

// The few-ULP transcendentals (sinCosPrecise, atan2Precise,
// acosPrecise: Vulkan's own may be off by thousands of ULP, lavapipe's are)
// and rotationYXY, rotX, rotY of core/rotation.cpp.
#include "common/sphere.glsl"
// RotationSample (core/shared_layout.h, shared with the host).
#include "haarcast/core/shared_layout.h"

layout(constant_id = kSpecLevel) const uint LEVEL = 5u;
layout(constant_id = kSpecThetaSamples) const uint THETA_SAMPLES = 16u;

const uint M = 1u << LEVEL;   // map side
const uint N = M * M;         // coefficients per map
const uint HALF = M / 2u;     // blocks per side at the finest detail level

layout(push_constant) uniform Push { RotationPush pushed; };

layout(std430, set = 0, binding = kRotateSamplesBinding) readonly buffer RotationSamples { RotationSample samples[]; };
layout(std430, set = 0, binding = kRotateSlicesBinding) readonly buffer Slices { float slices[]; };
layout(std430, set = 0, binding = kRotateMethodDataBinding) readonly buffer MethodData { uint methodData[]; };
// coherent: workgroups read back what their own invocations wrote (after
// memoryBarrierBuffer and barrier).
layout(std430, set = 0, binding = kRotateRotatedBinding) coherent buffer Rotated { float rotated[]; };

float methodFloat(uint word) { return uintBitsToFloat(methodData[word]); }

// Index of a detail coefficient in quadrant layout (shared_layout.h
// haarDetailIndex, HaarMap::detailIndexOf): band 0 = h, 1 = v, 2 = d.
uint detailIndex(uint band, uint l, uint i, uint j) { return haarDetailIndex(M, band, l, i, j); }

// Value of pixel (row, col) of the map whose coefficients start at base in
// `slices`: the inverse Haar transform at one pixel, O(log N). Every basis
// function is ±1/side on its support (the scaling function 1/M); h is + on
// the left half, v on the top half, d where both or neither (haar.h).
float slicePixel(uint base, uint row, uint col) {
  float value = slices[base] / float(M);
  for (uint l = 0u; l < LEVEL; ++l) {
    const uint side = M >> l;
    const uint i = row / side, j = col / side;
    const float sh = (col % side) < side / 2u ? 1.0 : -1.0;
    const float sv = (row % side) < side / 2u ? 1.0 : -1.0;
    const float h = slices[base + detailIndex(0u, l, i, j)];
    const float v = slices[base + detailIndex(1u, l, i, j)];
    const float d = slices[base + detailIndex(2u, l, i, j)];
    value += (sh * h + sv * v + sh * sv * d) / float(side);
  }
  return value;
}
