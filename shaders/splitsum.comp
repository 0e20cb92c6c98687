#version 450
// The "splitsum" pass (core/splitsum.h splitsumShade): per covered sample,
//   I_c = E_c(θₒ)·L_c(λ, m)·V,
// the image-based lighting of real-time engines: the lobes of the two
// nearest θₒ samples blended (shared::sliceBlendAt, blendLobes), m the
// mirror direction (0, cos θₒ, −sin θₒ) of the slice's frame turned by the
// sample's Y-X-Y rotation and the object's toLight into the light's frame,
// the prefiltered light read there trilinearly at λ = splitsumLevel(the
// lobe's median angle), and V the host's shadow ray along m (the mask's
// kLobeSeenBit, render/point_lights.h lobeRayBit).
//
// One invocation per sample, no shared memory and no barrier: a sample is
// two lobe reads and eight texel fetches. The invocations stride over the
// compacted samples (s = global id, + every invocation of the dispatch), so
// the dispatch is the rotation-input pass's indirect arguments, as fused's
// (FrameParams::fusedGroups caps its workgroups).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#include "haarcast/core/shared_layout.h"
#include "common/frame.glsl"
#include "common/sphere.glsl"

layout(local_size_x_id = kSpecLocalSize) in;
layout(constant_id = kSpecInterpolate) const uint INTERPOLATE = 1u;       // RenderOptions::interpolateSlices
layout(constant_id = kSpecPrefilterFinest) const uint PREFILTER_FINEST = 9u;  // the prefiltered light's finest level

layout(std430, set = 0, binding = kSplitsumSamplesBinding) readonly buffer Samples { RotationSample samples[]; };
layout(std430, set = 0, binding = kSplitsumShadeBinding) readonly buffer Shade { ShadeSample shade[]; };
layout(std430, set = 0, binding = kSplitsumObjectsBinding) readonly buffer Objects { ObjectInfo objects[]; };
layout(std430, set = 0, binding = kSplitsumCounterBinding) readonly buffer Counter { CoverageCounter counter; };
layout(std430, set = 0, binding = kSplitsumMasksBinding) readonly buffer Masks { uint masks[]; };  // sample s: kLobeSeenBit = its mirror ray escapes
// Object o's lobe t at ObjectInfo::sliceBase + t (core SliceLobe).
layout(std430, set = 0, binding = kSplitsumLobesBinding) readonly buffer Lobes { SliceLobe lobes[]; };
// Level l of the prefiltered light at prefilterOffset(l), RGB0 (core PrefilteredLight).
layout(set = 0, binding = kSplitsumLobeLightTexelsBinding) uniform textureBuffer lobeLight;
layout(std430, set = 0, binding = kSplitsumRadianceBinding) writeonly buffer Radiance { vec4 radiance[]; };

#include "common/prefiltered.glsl"

vec3 splitsumShade(uint s) {
  if ((masks[s] & kLobeSeenBit) == 0u) return vec3(0.0);
  const RotationSample rs = samples[s];
  const ObjectInfo o = objects[shade[s].object];
  const SliceBlend blend = sliceBlendAt(rs.thetaOut, o.thetaSamples, INTERPOLATE);
  // blendLobes of the two fields read: a SliceLobe copied whole (560 bytes,
  // twice) made lavapipe's compile of this pass take 22 s (docs/gpu.md).
  const uint a = o.sliceBase + blend.first, b = o.sliceBase + blend.second;
  const vec3 energy = lobes[a].energy.rgb + blend.weight * (lobes[b].energy.rgb - lobes[a].energy.rgb);
  const float median = lobes[a].median.x + blend.weight * (lobes[b].median.x - lobes[a].median.x);
  const vec2 sc = sinCosPrecise(rs.thetaOut);
  const mat3 toLight = mat3(o.toLight[0].xyz, o.toLight[1].xyz, o.toLight[2].xyz);
  const vec3 mirror = toLight * (rotationYXY(rs.alpha, rs.beta, rs.gamma) * vec3(0.0, sc.y, -sc.x));
  return energy * prefilteredAt(splitsumLevel(median), mirror);
}

void main() {
  const uint count = counter.covered;
  const uint stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  for (uint s = gl_GlobalInvocationID.x; s < count; s += stride) radiance[shade[s].pixel] = vec4(splitsumShade(s), 1.0);
}
