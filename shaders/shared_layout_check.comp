#version 450
// The shared header's Haar and lookup functions (core/shared_layout.h) evaluated by the
// device, for the test that compares their GLSL reading with the C++ one
// (tests/unit/gpu/shared_layout_test.cpp). Not part of any frame.
//
// Case k = (map level n, band, detail level l, block (i, j)) packed as
// (n, band·256 + l, i, j); five results per case:
//   [3k]     haarPreorderKey(n − 1, l, i, j) and the block haarPreorderBlock decodes
//   [3k + 1] haarChildSign(haarChildQuadrant(i, j)) as float bits, the quadrant
//   [3k + 2] haarDetailIndex(2^n, band, l, i, j) and its haarDetailPosition
//            (band, level, i·65536 + j)
//   [5k + 3] catmullRomWeights(t), t = (k mod 101)/101, as float bits
//   [5k + 4] pointFromMean(mean, up, down, left, right) with the five from
//            lookupInputs(k), and t, as float bits
// and, from invocation 0, the passes' interface (core/shared_passes.h) as
// this shader sees it, in binding 2: π and 2π as float bits, its own
// workgroup size, the numbers of kContract (sizes, levels, every pass's
// bindings and binding counts, in the C++ test's order), then the push
// block's RotationPush and BatchArgsPush members as the device read them.
#extension GL_GOOGLE_include_directive : require
#include "haarcast/core/shared_layout.h"
#include "haarcast/core/shared_tonemap.h"

layout(local_size_x = kLocalSize) in;
layout(push_constant) uniform Push {
  uint count;
  uint pad0;
  uint pad1;
  uint pad2;
  RotationPush rotation;
  BatchArgsPush batchArgs;
} pc;
layout(std430, set = 0, binding = 0) readonly buffer Cases { uvec4 cases[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Results { uvec4 results[]; };
layout(std430, set = 0, binding = 2) writeonly buffer Contract { uint contract[]; };

const uint kContract[] = uint[](
    kLocalSize, kGpuLocalSize, kMinLevel, kFusedMaxLevel, kRotationMaxLevel, kRotationInputFrameBinding,
    kRotationInputObjectsBinding, kRotationInputIdsBinding, kRotationInputNormalsBinding,
    kRotationInputTrianglesBinding, kRotationInputSamplesBinding, kRotationInputShadeBinding,
    kRotationInputCounterBinding, kRotationInputSubIdsBinding, kRotationInputSubNormalsBinding,
    kRotationInputEdgesBinding, kRotationInputBindings, kResolveFrameBinding, kResolveIdsBinding,
    kResolveRadianceBinding, kResolveBackgroundBinding, kResolveEdgesBinding, kResolveBindings,
    kExposureFrameBinding, kExposureIdsBinding, kExposureRadianceBinding, kExposureResultBinding,
    kExposureBindings, kTonemapFrameBinding, kTonemapRadianceBinding, kTonemapRgba8Binding,
    kTonemapThresholdsBinding, kTonemapExposureBinding, kTonemapBindings, kRotateSamplesBinding,
    kRotateSlicesBinding, kRotateMethodDataBinding, kRotateRotatedBinding, kRotateBindings,
    kTripleProductShadeBinding, kTripleProductRotatedBinding, kTripleProductLightBinding,
    kTripleProductVisibilityBinding, kTripleProductRadianceBinding, kTripleProductCounterBinding,
    kTripleProductBindings, kBatchArgsCounterBinding, kBatchArgsArgsBinding, kBatchArgsBindings,
    kFusedSamplesBinding, kFusedShadeBinding, kFusedObjectsBinding, kFusedSliceTexelsBinding,
    kFusedLightTexelsBinding, kFusedVisibilityTexelsBinding, kFusedDirectionTexelsBinding,
    kFusedPointLightsBinding, kFusedRadianceBinding, kFusedCounterBinding, kFusedMasksBinding,
    kFusedSliceEnergyBinding, kFusedLobesBinding, kFusedLobeLightTexelsBinding, kFusedPointSliceTexelsBinding,
    kFusedBindings, kSplitsumSamplesBinding, kSplitsumShadeBinding, kSplitsumObjectsBinding,
    kSplitsumCounterBinding, kSplitsumMasksBinding, kSplitsumLobesBinding, kSplitsumLobeLightTexelsBinding,
    kSplitsumRadianceBinding, kSplitsumBindings, kGBufferPositionsBinding, kGBufferNormalsBinding,
    kGBufferTrianglesBinding, kGBufferBindings, kExposureLocalSize, kSpecLevel, kSpecThetaSamples, kSpecLocalSize,
    kSpecInterpolate, kSpecPrefilterFinest, kToneCodes);

void writeContract() {
  uint w = 0u;
  contract[w++] = floatBitsToUint(kPiF);
  contract[w++] = floatBitsToUint(kTwoPiF);
  contract[w++] = gl_WorkGroupSize.x;
  for (uint i = 0u; i < uint(kContract.length()); ++i) contract[w++] = kContract[i];
  contract[w++] = pc.rotation.first;
  contract[w++] = pc.rotation.count;
  contract[w++] = pc.rotation.pad0;
  contract[w++] = pc.rotation.pad1;
  contract[w++] = pc.batchArgs.batch;
  contract[w++] = pc.batchArgs.batches;
  contract[w++] = pc.batchArgs.pad0;
  contract[w++] = pc.batchArgs.pad1;
}

// Five lookup inputs from a case index, the same in the C++ test.
float lookupInput(uint k, uint s) { return float((k * (7u + 2u * s) + 3u * s) % 53u) / 13.0; }

void main() {
  const uint k = gl_GlobalInvocationID.x;
  if (k == 0u) writeContract();
  if (k >= pc.count) return;
  const uvec4 c = cases[k];
  const uint n = c.x, band = c.y >> 8u, l = c.y & 255u, i = c.z, j = c.w;

  const uint key = haarPreorderKey(n - 1u, l, i, j);
  const HaarBlock block = haarPreorderBlock(n - 1u, key);
  results[5u * k] = uvec4(key, block.level, block.i, block.j);

  const uint quadrant = haarChildQuadrant(i, j);
  results[5u * k + 1u] = uvec4(floatBitsToUint(haarChildSign(quadrant)), quadrant);

  const uint index = haarDetailIndex(1u << n, band, l, i, j);
  const HaarDetailPosition p = haarDetailPosition(n, index);
  results[5u * k + 2u] = uvec4(index, p.band, p.level, (p.i << 16u) | p.j);

  const float t = float(k % 101u) / 101.0;
  results[5u * k + 3u] = floatBitsToUint(catmullRomWeights(t));
  const float point = pointFromMean(lookupInput(k, 0u), lookupInput(k, 1u), lookupInput(k, 2u), lookupInput(k, 3u),
                                    lookupInput(k, 4u));
  results[5u * k + 4u] = uvec4(floatBitsToUint(point), floatBitsToUint(t), 0u, 0u);
}
