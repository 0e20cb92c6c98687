#version 450
// The "triple-product" pass: per covered pixel and channel,
//   radiance_c = Σ_v b_v · tripleProduct(light_c, rotated_c, visibility_v)
// over the hit triangle's three vertices (the visibility blend is linear, so
// it distributes over the product, as in cpu_renderer.cpp). One invocation
// per (sample, channel) of the current rotation batch; local size kLocalSize.
#extension GL_GOOGLE_include_directive : require
#include "common/frame.glsl"

layout(local_size_x = kLocalSize) in;
layout(constant_id = kSpecLevel) const int LEVEL = 5;
const int M = 1 << LEVEL;
const int N = M * M;

layout(push_constant) uniform Push { RotationPush pc; };

layout(std430, set = 0, binding = kTripleProductShadeBinding) readonly buffer Shade { ShadeSample shade[]; };
layout(std430, set = 0, binding = kTripleProductRotatedBinding) readonly buffer Rotated { float rotated[]; };
layout(std430, set = 0, binding = kTripleProductLightBinding) readonly buffer Light { uvec4 light[]; };       // headers [object·3 + c], then blocks
layout(std430, set = 0, binding = kTripleProductVisibilityBinding) readonly buffer Visibility { uvec4 vis[]; };    // headers [vertex], then blocks
layout(std430, set = 0, binding = kTripleProductRadianceBinding) buffer Radiance { vec4 radiance[]; };           // per pixel, linear RGB
layout(std430, set = 0, binding = kTripleProductCounterBinding) readonly buffer Counter { CoverageCounter counter; };

#define BRDF(i) rotated[i]
#include "common/triple_product.glsl"

float tripleProduct(uvec4 lightHeader, uint brdfBase, uvec4 visHeader) {
  const int finest = LEVEL - 1;
  // Term 1: all three scaling, C = 1/M.
  float a0 = uintBitsToFloat(lightHeader.z);
  float b0 = BRDF(brdfBase);
  float c0 = uintBitsToFloat(visHeader.z);
  float sum = a0 * b0 * c0 / float(M);

  // The root-to-block path: block coordinates, the three scaling values and
  // the light's and visibility's details per detail level.
  int pathI[kTpMaxLevels], pathJ[kTpMaxLevels];
  float sA[kTpMaxLevels], sB[kTpMaxLevels], sC[kTpMaxLevels];
  vec3 detA[kTpMaxLevels], detC[kTpMaxLevels];
  pathI[0] = 0;
  pathJ[0] = 0;
  sA[0] = a0;
  sB[0] = b0;
  sC[0] = c0;
  detA[0] = vec3(0.0);
  detC[0] = vec3(0.0);
  int depth = 1;

  uint ia = 0u, ic = 0u;
  const uint kNone = 0xffffffffu;
  while (ia < lightHeader.y || ic < visHeader.y) {
    uvec4 ea = ia < lightHeader.y ? light[lightHeader.x + ia] : uvec4(kNone);
    uvec4 ec = ic < visHeader.y ? vis[visHeader.x + ic] : uvec4(kNone);
    uint key = min(ea.x, ec.x);  // merge of two pre-ordered lists

    const HaarBlock block = haarPreorderBlock(uint(finest), key);
    int l = int(block.level);
    int bi = int(block.i);
    int bj = int(block.j);

    // Deepest level shared with the current path, then descend to the block.
    int common_ = min(depth - 1, l);
    while (pathI[common_] != (bi >> (l - common_)) || pathJ[common_] != (bj >> (l - common_))) --common_;
    for (int d = common_ + 1; d <= l; ++d) {
      int ci = bi >> (l - d);
      int cj = bj >> (l - d);
      vec3 sign_ = haarChildSign(haarChildQuadrant(uint(ci), uint(cj)));
      vec3 detB = brdfDetails(brdfBase, d - 1, pathI[d - 1], pathJ[d - 1]);
      sA[d] = 0.5 * (sA[d - 1] + dot(sign_, detA[d - 1]));
      sB[d] = 0.5 * (sB[d - 1] + dot(sign_, detB));
      sC[d] = 0.5 * (sC[d - 1] + dot(sign_, detC[d - 1]));
      pathI[d] = ci;
      pathJ[d] = cj;
      detA[d] = vec3(0.0);
      detC[d] = vec3(0.0);
    }
    depth = l + 1;

    vec3 a = vec3(0.0), c = vec3(0.0);
    if (ea.x == key) {
      a = uintBitsToFloat(ea.yzw);
      ++ia;
    }
    if (ec.x == key) {
      c = uintBitsToFloat(ec.yzw);
      ++ic;
    }
    detA[l] = a;
    detC[l] = c;

    // Terms 2 and 3 for this block, C = ±1/s with s = 2^(n−l).
    vec3 b = brdfDetails(brdfBase, l, bi, bj);
    float sameType = dot(a * b, vec3(sC[l])) + dot(a * c, vec3(sB[l])) + dot(b * c, vec3(sA[l]));
    float allTypes = a.x * (b.y * c.z + b.z * c.y) + a.y * (b.x * c.z + b.z * c.x) + a.z * (b.x * c.y + b.y * c.x);
    sum += (sameType + allTypes) / float(1 << (LEVEL - l));
  }
  return sum;
}

void main() {
  uint gid = gl_GlobalInvocationID.x;
  // The batch's samples: the indirect dispatch (batch_args.comp) covers
  // them in groups of kLocalSize, so the last group's extra invocations stop here.
  const uint covered = counter.covered;
  const uint count = covered > pc.first ? min(pc.count, covered - pc.first) : 0u;
  if (gid >= count * 3u) return;
  uint local = gid / 3u;
  uint c = gid % 3u;
  ShadeSample s = shade[pc.first + local];
  uvec4 lightHeader = light[s.object * 3u + c];
  uint brdfBase = (local * 3u + c) * uint(N);
  float sum = s.b[0] * tripleProduct(lightHeader, brdfBase, vis[s.vertex[0]]) +
              s.b[1] * tripleProduct(lightHeader, brdfBase, vis[s.vertex[1]]) +
              s.b[2] * tripleProduct(lightHeader, brdfBase, vis[s.vertex[2]]);
  radiance[s.pixel][c] = sum;
}
