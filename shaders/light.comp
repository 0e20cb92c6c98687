#version 450
// `fused`'s "light" stage: one object's light in its own frame this frame,
// the light texels fused.comp reads (core/shared_light.h has the phases and
// what they compute; render::resolveFusedLight is the same on the host, in
// double, for the CPU backend). Each launch is one object's, so that its
// level, its rest map and its ground are uniform over the launch.
#extension GL_GOOGLE_include_directive : require
#include "haarcast/core/shared_layout.h"
#include "haarcast/core/shared_cells.h"
#include "common/sphere.glsl"

layout(local_size_x = kLocalSize) in;
layout(push_constant) uniform Push { LightPush pc; };

layout(std430, set = 0, binding = kLightObjectsBinding) buffer Objects { ObjectInfo objects[]; };
layout(std430, set = 0, binding = kLightRestBinding) readonly buffer Rest { vec4 rest[]; };
// Per texel of each level in use (the objects' and the turn levels'): its
// centre's direction (xyz) and solid angle (w).
layout(std430, set = 0, binding = kLightDirectionsBinding) readonly buffer Directions { vec4 directions[]; };
layout(std430, set = 0, binding = kLightTexelsBinding) buffer Light { vec4 light[]; };

// The rest map at the turn level, looked up along M·ω for its texel k
// (its centre's direction ω): SphereMap::sampleBilinear's sum, in its order.
vec3 turned(mat3 toLight, uint k) {
  const vec2 src = directionToSpherical(toLight * directions[pc.restDirections + k].xyz);
  const Taps t = bilinearTaps(int(pc.restLevel), src.x, src.y);
  const uint width = 1u << pc.restLevel;
  const vec3 a = rest[pc.restBase + uint(t.rc.x) * width + uint(t.rc.z)].rgb;
  const vec3 b = rest[pc.restBase + uint(t.rc.x) * width + uint(t.rc.w)].rgb;
  const vec3 c = rest[pc.restBase + uint(t.rc.y) * width + uint(t.rc.z)].rgb;
  const vec3 d = rest[pc.restBase + uint(t.rc.y) * width + uint(t.rc.w)].rgb;
  const vec3 top = (1.0 - t.t.y) * a + t.t.y * b;
  const vec3 bottom = (1.0 - t.t.y) * c + t.t.y * d;
  return (1.0 - t.t.x) * top + t.t.x * bottom;
}

// Texel k of the object's level: the turned map averaged over its f × f
// fine texels by solid angle (SphereMap::downsampled), times its own ΔΩ
// (SphereMap::weightedBySolidAngle), zero below the ground's plane.
void texel(ObjectInfo o, uint k) {
  const uint m = 1u << o.level;
  const uint row = k / m, col = k % m;
  const uint f = 1u << (pc.restLevel - o.level);
  const uint fineWidth = m * f;
  const mat3 toLight = mat3(o.toLight[0].xyz, o.toLight[1].xyz, o.toLight[2].xyz);
  vec3 sum = vec3(0.0);
  float band = 0.0;
  for (uint di = 0u; di < f; ++di) {
    const uint fine = (row * f + di) * fineWidth + col * f;
    vec3 fineRowSum = vec3(0.0);
    for (uint dj = 0u; dj < f; ++dj) fineRowSum += turned(toLight, fine + dj);
    const float omega = directions[pc.restDirections + fine].w;  // the fine row's ΔΩ
    sum += fineRowSum * omega;
    band += omega;
  }
  const vec4 centre = directions[o.directionBase + k];
  vec3 value = sum / (band * float(f)) * centre.w;
  if (pc.groundUp.w > 0.0 && dot(centre.xyz, pc.groundUp.xyz) < 0.0) value = vec3(0.0);
  light[o.lightBase + k] = vec4(value, 0.0);
}

// Cell q: its power P_c = Σ L_c·ΔΩ over its directions, and their
// centroid weighted by Σ_c L_c·ΔΩ, or its centre where it is black
// (CellLight::fromPlanes, in its order).
void cell(ObjectInfo o, uint q) {
  const uint m = 1u << o.level;
  vec3 power = vec3(0.0), weighted = vec3(0.0);
  for (uint k = 0u; k < kCellDirections; ++k) {
    const uint i = cellDirection(m, q, k);
    const vec3 l = light[o.lightBase + i].rgb;
    power += l;
    weighted += (l.r + l.g + l.b) * directions[o.directionBase + i].xyz;
  }
  const float norm = length(weighted);
  const vec3 at = norm > 0.0 ? weighted / norm : directions[o.directionBase + cellCentreTexel(m, q)].xyz;
  light[o.lightBase + cellPowerTexel(m, q)] = vec4(power, 0.0);
  light[o.lightBase + cellCentroidTexel(m, q)] = vec4(at, 0.0);
}

// The ground's flat radiance ρ·Σ_{rows with y > 0} Σ_cols (L·ΔΩ)·y, in the
// host's order, by one invocation: half a ground's map is at most 8,192
// texels, and a workgroup's reduction would put barriers into a shader
// that otherwise has none (a CPU device compiles those into coroutines).
void ground(ObjectInfo o) {
  const uint m = 1u << o.level;
  vec3 sum = vec3(0.0);
  for (uint row = 0u; row < m; ++row) {
    const float y = directions[o.directionBase + row * m].y;  // cos θ of the row
    if (y <= 0.0) continue;
    for (uint col = 0u; col < m; ++col) sum += light[o.lightBase + row * m + col].rgb * y;
  }
  objects[pc.object].groundRadiance = vec4(pc.albedo.rgb * sum, 0.0);
}

void main() {
  const ObjectInfo o = objects[pc.object];
  const uint m = 1u << o.level;
  const uint id = gl_GlobalInvocationID.x;
  if (pc.phase == kLightPhaseTexels) {
    if (id < m * m) texel(o, id);
  } else if (pc.phase == kLightPhaseCells) {
    if (id < cellsAcross(m) * cellsAcross(m)) cell(o, id);
  } else if (pc.phase == kLightPhaseGround) {
    if (id == 0u) ground(o);
  }
}
