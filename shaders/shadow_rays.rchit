#version 460
// The closest hit of a ray that asks which object it hit
// (shadow_rays.rgen occludedBySelf): payload location 1.
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
#include "ray_hit.glsl"

layout(location = 1) rayPayloadInEXT ObjectHit objectHit;

void main() { objectHit = ObjectHit(gl_InstanceCustomIndexEXT, gl_HitTEXT); }
