#version 460
// The shadow rays' miss shader (shadow_rays.rgen): a ray that leaves the
// scene is not blocked.
#extension GL_EXT_ray_tracing : require

layout(location = 0) rayPayloadInEXT uint blocked;

void main() { blocked = 0u; }
