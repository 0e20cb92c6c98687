// `fused`'s light on the device (shaders/light.comp, gpu fused_light.cpp):
// each object's light in its own frame, every frame, as the host's
// render::resolveFusedLight makes it for the CPU backend. Part of
// shared_layout.h, which includes it inside its namespace with its macros:
// include that instead.
//
// What one object's light is (renderer.cpp resolveFusedLight, DESIGN.md):
//   L_obj(ω) = L(M·ω), M = lightRotationᵀ·objectRotation (ObjectInfo::toLight),
// the rest map (the light less its point lights) looked up bilinearly at the
// pixel centres of a map two levels finer than the object's (its "turn"
// level, render::lightTurnLevel), averaged down to the object's level by
// solid angle (SphereMap::downsampled), times the texel's solid angle ΔΩ,
// zero below the ground's plane for an object standing on one; for the
// ground itself, its closed form's flat radiance ρ·Σ_{y>0} (L·ΔΩ)·y. The
// launches of one pipeline, told apart by LightPush::phase, one object each:
//   kLightPhaseTexels  per texel of the object's level: L·ΔΩ (RGB), into
//                      the light texels at ObjectInfo::lightBase;
//   kLightPhaseCells   per cell (shared_cells.h), by cells only: its power
//                      and light-weighted centroid after the texels
//                      (core CellLight::fromPlanes);
//   kLightPhaseGround  one workgroup, the ground only: the flat radiance
//                      into ObjectInfo::groundRadiance.
#ifndef HAARCAST_CORE_SHARED_LIGHT_H
#define HAARCAST_CORE_SHARED_LIGHT_H

HC_CONST uint kLightPhaseTexels = 0u;
HC_CONST uint kLightPhaseCells = 1u;
HC_CONST uint kLightPhaseGround = 2u;

// light.comp's bindings, all storage buffers. The directions are fused's
// table (gpu::pixelCentreDirections), which holds each object's level and
// each turn level: a texel's centre (xyz) and solid angle (w), computed in
// double on the host.
HC_CONST uint kLightObjectsBinding = 0u;     // ObjectInfo[]; the ground's groundRadiance written
HC_CONST uint kLightRestBinding = 1u;        // vec4: the rest maps (RGB), each turn level's row-major from its base
HC_CONST uint kLightDirectionsBinding = 2u;  // vec4: the direction table
HC_CONST uint kLightTexelsBinding = 3u;      // vec4: the light texels fused.comp reads, written
HC_CONST uint kLightBindings = 4u;

struct LightPush {
  uint phase;
  uint object;
  uint restBase;        // the object's turn-level rest map at this vec4 of kLightRestBinding
  uint restLevel;       // its level (≥ ObjectInfo::level)
  uint restDirections;  // that level's direction 0 in the direction table
  uint pushPad0;
  uint pushPad1;
  uint pushPad2;
  // xyz: the ground's normal in the object's frame; w: 1 where the object
  // stands on a ground (its light is zero below that plane), else 0.
  vec4 groundUp;
  vec4 albedo;  // the ground: its Lambert ρ = albedo/π (rgb); else 0
};

#endif  // HAARCAST_CORE_SHARED_LIGHT_H
