#version 450
// The "gbuffer" pass, vertex stage. Non-indexed triangle list with no vertex
// buffers: vertex k of the draw is corner k % 3 of triangle k / 3, fetched
// through the object's index list, so the fragment stage gets the exact
// barycentrics (corner one-hot, interpolated perspective-correct) and the
// triangle id without any extension.
#extension GL_GOOGLE_include_directive : require
#include "haarcast/core/shared_layout.h"
layout(push_constant) uniform Push { GBufferPush pc; };

layout(std430, set = 0, binding = kGBufferPositionsBinding) readonly buffer Positions { vec4 positions[]; };  // object frame, global vertex ids
layout(std430, set = 0, binding = kGBufferNormalsBinding) readonly buffer Normals { vec4 normals[]; };
layout(std430, set = 0, binding = kGBufferTrianglesBinding) readonly buffer Triangles { uint triangles[]; };

layout(location = 0) out vec3 outNormal;
layout(location = 1) out vec3 outPosition;
layout(location = 2) out vec2 outBary;  // weights of corners 1 and 2 (Embree's u, v)
layout(location = 3) flat out uint outTriangle;

void main() {
  uint triangle = uint(gl_VertexIndex) / 3u;
  uint corner = uint(gl_VertexIndex) % 3u;
  uint v = triangles[3u * (pc.triangleBase + triangle) + corner];
  vec3 p = positions[v].xyz;
  outNormal = normals[v].xyz;
  outPosition = p;
  outBary = vec2(corner == 1u ? 1.0 : 0.0, corner == 2u ? 1.0 : 0.0);
  outTriangle = triangle;
  gl_Position = pc.objectToClip * vec4(p, 1.0);
}
