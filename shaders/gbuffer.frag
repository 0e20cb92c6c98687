#version 450
// The "gbuffer" pass, fragment stage: object-frame normal and position,
// object id + 1 (0 = background), triangle id within the object and the
// barycentrics (u, v) as float bits.
#extension GL_GOOGLE_include_directive : require
#include "haarcast/core/shared_layout.h"
layout(push_constant) uniform Push { GBufferPush pc; };

layout(location = 0) in vec3 inNormal;
layout(location = 1) in vec3 inPosition;
layout(location = 2) in vec2 inBary;
layout(location = 3) flat in uint inTriangle;

layout(location = 0) out vec4 outNormal;
layout(location = 1) out uvec4 outIds;
layout(location = 2) out vec4 outPosition;

void main() {
  outNormal = vec4(inNormal, 0.0);
  outIds = uvec4(pc.objectId + 1u, inTriangle, floatBitsToUint(inBary.x), floatBitsToUint(inBary.y));
  outPosition = vec4(inPosition, 1.0);
}
