#version 450
// The shared header's Haar functions (core/shared_layout.h) evaluated by the
// device, for the test that compares their GLSL reading with the C++ one
// (tests/unit/gpu/shared_layout_test.cpp). Not part of any frame.
//
// Case k = (map level n, band, detail level l, block (i, j)) packed as
// (n, band·256 + l, i, j); three results per case:
//   [3k]     haarPreorderKey(n − 1, l, i, j) and the block haarPreorderBlock decodes
//   [3k + 1] haarChildSign(haarChildQuadrant(i, j)) as float bits, the quadrant
//   [3k + 2] haarDetailIndex(2^n, band, l, i, j) and its haarDetailPosition
//            (band, level, i·65536 + j)
#extension GL_GOOGLE_include_directive : require
#include "haarcast/core/shared_layout.h"

layout(local_size_x = 64) in;
layout(push_constant) uniform Push { uint count; } pc;
layout(std430, set = 0, binding = 0) readonly buffer Cases { uvec4 cases[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Results { uvec4 results[]; };

void main() {
  const uint k = gl_GlobalInvocationID.x;
  if (k >= pc.count) return;
  const uvec4 c = cases[k];
  const uint n = c.x, band = c.y >> 8u, l = c.y & 255u, i = c.z, j = c.w;

  const uint key = haarPreorderKey(n - 1u, l, i, j);
  const HaarBlock block = haarPreorderBlock(n - 1u, key);
  results[3u * k] = uvec4(key, block.level, block.i, block.j);

  const uint quadrant = haarChildQuadrant(i, j);
  results[3u * k + 1u] = uvec4(floatBitsToUint(haarChildSign(quadrant)), quadrant);

  const uint index = haarDetailIndex(1u << n, band, l, i, j);
  const HaarDetailPosition p = haarDetailPosition(n, index);
  results[3u * k + 2u] = uvec4(index, p.band, p.level, (p.i << 16u) | p.j);
}
