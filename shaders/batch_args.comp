#version 450
// The rotating methods' batches sized on the device (shared_layout.h
// DispatchArgs): from the covered count that rotation_input.comp left in the
// counter, batch b of `batch` samples gets the rotation's indirect arguments
// (count_b, 3, 1) at [b] and the triple product's (⌈3·count_b / kLocalSize⌉, 1, 1)
// at [batches + b], count_b = clamp(covered − b·batch, 0, batch). A batch
// past the covered pixels dispatches nothing, so the host records every
// batch the resolution can need and never reads the count mid-frame.
#extension GL_GOOGLE_include_directive : require
#include "haarcast/core/shared_layout.h"

layout(local_size_x = kLocalSize) in;
layout(push_constant) uniform Push { BatchArgsPush pc; };

layout(std430, set = 0, binding = kBatchArgsCounterBinding) readonly buffer Counter { CoverageCounter counter; };
layout(std430, set = 0, binding = kBatchArgsArgsBinding) writeonly buffer Args { DispatchArgs args[]; };

void main() {
  const uint b = gl_GlobalInvocationID.x;
  if (b >= pc.batches) return;
  const uint covered = counter.covered;
  const uint first = b * pc.batch;
  const uint count = covered > first ? min(pc.batch, covered - first) : 0u;
  DispatchArgs rotation;
  rotation.groups[0] = count;
  rotation.groups[1] = 3u;
  rotation.groups[2] = 1u;
  rotation.pad = 0u;
  DispatchArgs product;
  product.groups[0] = (3u * count + kLocalSize - 1u) / kLocalSize;
  product.groups[1] = 1u;
  product.groups[2] = 1u;
  product.pad = 0u;
  args[b] = rotation;
  args[pc.batches + b] = product;
}
