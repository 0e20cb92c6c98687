#version 460
// The miss shader of the rays that ask which object they hit
// (shadow_rays.rgen occludedBySelf, miss index 1): none.
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
#include "ray_hit.glsl"

layout(location = 1) rayPayloadInEXT ObjectHit objectHit;

void main() { objectHit = ObjectHit(kNoObject, 0.0); }
