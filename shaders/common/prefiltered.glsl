// The prefiltered light (core/prefiltered_light.h) as a shader reads it:
// level l's texels at prefilterOffset(l), RGB0, in a texel buffer. The
// includer declares, before this file:
//   uniform textureBuffer lobeLight;     the texels
//   const uint PREFILTER_FINEST;         the light's finest level (a spec constant)
// splitsum.comp and fused.comp's lobe path read it through these.
#ifndef HAARCAST_PREFILTERED_GLSL
#define HAARCAST_PREFILTERED_GLSL

#include "common/sphere.glsl"

// Level `level` bilinear at direction d (PrefilteredLight::sampleLevel).
vec3 prefilteredAt(uint level, vec3 d) {
  const LatLongTaps t = latLongTaps(level, atan2Fast(sqrt(d.x * d.x + d.z * d.z), d.y), atan2Fast(d.x, d.z));
  const int base = int(prefilterOffset(level)), m = int(1u << level);
  const vec3 a = texelFetch(lobeLight, base + int(t.row0) * m + int(t.col0)).rgb;
  const vec3 b = texelFetch(lobeLight, base + int(t.row0) * m + int(t.col1)).rgb;
  const vec3 c = texelFetch(lobeLight, base + int(t.row1) * m + int(t.col0)).rgb;
  const vec3 e = texelFetch(lobeLight, base + int(t.row1) * m + int(t.col1)).rgb;
  const vec3 top = t.tCol * (b - a) + a;
  const vec3 bottom = t.tCol * (e - c) + c;
  return t.tRow * (bottom - top) + top;
}

// Trilinear: ⌊λ⌋ and ⌊λ⌋ + 1 blended by λ's fraction (PrefilteredLight::sample).
vec3 prefilteredAt(float level, vec3 d) {
  const float lambda = clamp(level, 0.0, float(PREFILTER_FINEST));
  const uint l0 = uint(lambda);
  const float t = lambda - float(l0);
  const vec3 a = prefilteredAt(l0, d);
  if (t == 0.0 || l0 == PREFILTER_FINEST) return a;
  return a + t * (prefilteredAt(l0 + 1u, d) - a);
}

#endif
