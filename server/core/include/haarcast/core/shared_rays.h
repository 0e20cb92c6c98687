// Shadow rays on the device (shaders/shadow_rays.rgen, gpu/ray_tracing.h):
// what the ray-generation shader reads, laid out once for C++ and GLSL. Part
// of shared_layout.h, which includes it inside its namespace with its
// macros: include that instead.
//
// The rays are the host's (render/point_lights.h) for the same samples:
// each sample's point-light rays, the lobe ray, and the ground's hidden-sky
// rays, on the same coarse grid, from the same shading points. The pass
// runs in launches of one pipeline, told apart by RaysPush::phase:
//   kRaysPhaseCentres  per covered sample: a pixel's centre sample into
//                      pixelSample[pixel] (cleared to ~0 before);
//   kRaysPhaseGrid     per grid point (RayFrame::gridColumns × gridRows):
//                      −1 unless an interior ground pixel, whose hidden
//                      sky is a sky job (below);
//   kRaysPhaseFineGrid per fine grid point (fineColumns × fineRows): the
//                      same, where a coarse cell an outline crosses uses it;
//   kRaysPhaseMasks    per covered sample: its shadow word (fused.comp's
//                      `masks`), the ground's occlusion blended from the
//                      grid, or, where the grid cannot, a sky job of its own;
//   kRaysPhaseSkyRays  each sky job's cone rays, over kSkyLanes invocations;
//   kRaysPhaseSkySums  per sky job: its lanes' sums, written to its grid
//                      point or into its sample's word;
//   kRaysPhaseHidden   per sample a smooth-sum stage sums itself: the sky
//                      other objects hide from it (RaysPush::stagedHidden).
// A ground point's hidden sky is up to 256 rays per occluder. Traced in
// one invocation, the few thousand grid points left a GPU nearly empty
// while each walked its rays one after another, at every frame size; a sky
// job spreads them over kSkyLanes invocations instead, so the grid, the
// fine grid and the samples' own rays are each one short chain of rays.
#ifndef HAARCAST_CORE_SHARED_RAYS_H
#define HAARCAST_CORE_SHARED_RAYS_H

HC_CONST uint kRaysPhaseCentres = 0u;
HC_CONST uint kRaysPhaseGrid = 1u;
HC_CONST uint kRaysPhaseMasks = 2u;
HC_CONST uint kRaysPhaseFineGrid = 3u;
HC_CONST uint kRaysPhaseSkyRays = 4u;
HC_CONST uint kRaysPhaseSkySums = 5u;
// Between a smooth-sum stage's two `fused` dispatches: the HiddenLight of
// each sample the stage sums itself (its list of own sums).
HC_CONST uint kRaysPhaseHidden = 6u;

// A sky job: the hidden sky of the shading point of covered sample
// `from`, for `target`: a point of `grid` (coarse, then fine), or, with
// kSkyJobWord, that sample's shadow word. Lane l of a job traces the rays
// whose index over all its cones (occluder, ring, sector, in the host's
// order) is l modulo kSkyLanes, and writes their sum to partials[job·kSkyLanes + l];
// kRaysPhaseSkySums adds the lanes in order. Jobs past the list's capacity
// (RayFrame::skyJobCapacity) are traced where they arise, in one invocation.
HC_CONST uint kSkyLanes = 32u;
HC_CONST uint kSkyJobWord = 0x80000000u;
// The kRaysPhaseSkyRays launch: kSkyJobsAcross jobs a row of kSkyLanes·kSkyJobsAcross
// invocations, at most kSkyJobsInFlight jobs at once (each invocation
// takes its job, then every one so many further on).
HC_CONST uint kSkyJobsAcross = 64u;
HC_CONST uint kSkyJobsInFlight = 4096u;
struct SkyJob {
  uint from;
  uint target;
};

// The ground grid's refinement (render::GroundSkyGrid): a coarse cell that
// an object's outline crosses (a corner off the ground) is read from a grid
// this much finer, traced only where such a cell needs it, and a fine cell
// that the outline crosses too takes its samples' own rays. Fine point k
// is a corner of fine cells k − 1 and k: pixels max(0, (k − 1)·fine) up to
// min((k + 1)·fine, extent) − 1, in coarse cells first…last of these.
HC_FUNCTION uint groundSkyFineStep(uint coarse) { return max(2u, coarse / 4u); }
HC_FUNCTION uint groundFineFirstCell(uint k, uint fine, uint coarse) { return (k > 0u ? (k - 1u) * fine : 0u) / coarse; }
HC_FUNCTION uint groundFineLastCell(uint k, uint fine, uint coarse, uint extent) {
  return (min((k + 1u) * fine, extent) - 1u) / coarse;
}

// The ground's hidden-sky rays per occluder (render::groundSkyOcclusion):
// (kGroundSkyRings·m) × (kGroundSkySectors·m) directions in its bounding
// cone, m = groundSkyScale(the cone's solid angle): 16 rays for a narrow
// cone, up to 256 for the hemisphere a point inside the bounding sphere
// sees. With 16 rays everywhere, a ground point beside an object (its cone
// a hemisphere, every ray hitting the body) counted the whole sky hidden and
// went black; the rays must resolve the body's outline in a wide cone.
HC_CONST uint kGroundSkyRings = 2u;
HC_CONST uint kGroundSkySectors = 8u;
HC_CONST uint kGroundSkyMaxScale = 4u;
HC_CONST float kGroundSkySolidPerScale = 0.4f;  // sr: m² cones of this solid angle share one m
HC_FUNCTION uint groundSkyScale(float solidAngle) {
  const float m = ceil(sqrt(max(solidAngle, 0.0f) / kGroundSkySolidPerScale));
  return uint(clamp(m, 1.0f, float(kGroundSkyMaxScale)));
}

// The sky another object hides from an object's pixel (render::objectSkyHidden):
// the same cone rays as the ground's, toward every other object's bounding
// sphere, fewer of them (a pixel's own rays, no grid between: 2 × 8 a
// cone, which gave the same figures as 4 × 16 on the scenes of
// docs/design.md for a fifth of the rays), counted
// where the other object blocks the ray and the pixel's own object does not
// (what it hides from itself is its own visibility already).
HC_CONST uint kObjectSkyMaxScale = 1u;

// The sky other objects hide from a sample: power_c = Σ L_c·cos·ΔΩ over
// the hidden directions, the irradiance they would give, which `fused`
// takes off as a diffuse surface of the slice's albedo would lose it:
// I_c −= power_c·E_c/π, E_c = ∫ρ_c·cos dω of the pass's part of the lobe.
// Exact for a Lambert surface (E = its albedo); for a glossy one the
// lobe's shape within the hidden sky is not followed. (Read as a light at
// the hidden directions' mean, power·ρ(d), a glossy lobe near d took off
// the whole of a wide hidden cone at its peak: black spots.) `direction`
// is that mean (luminance·ΔΩ-weighted, the object's frame), packed: where
// the hidden sky lies, for diagnostics. power = 0: nothing hidden.
struct HiddenLight {
  vec3 power;
  uint direction;  // packDirection(the mean hidden direction)
};

// A unit direction in one word: its octahedral projection, 16 bits an axis
// (about 1e-4 rad apart); the same integer arithmetic in both languages.
HC_FUNCTION uint packUnit16(float x) { return uint(floor(clamp(x, -1.0f, 1.0f) * 32767.0f + 32767.5f)); }
HC_FUNCTION float unpackUnit16(uint u) { return (float(u) - 32767.0f) / 32767.0f; }
HC_FUNCTION float signNotZero(float x) { return x >= 0.0f ? 1.0f : -1.0f; }
HC_FUNCTION uint packDirection(vec3 d) {
  const float s = abs(d.x) + abs(d.y) + abs(d.z);
  float u = s > 0.0f ? d.x / s : 0.0f;
  float v = s > 0.0f ? d.y / s : 0.0f;
  if (d.z < 0.0f) {  // the lower half folded over the diagonals
    const float fu = (1.0f - abs(v)) * signNotZero(u);
    v = (1.0f - abs(u)) * signNotZero(v);
    u = fu;
  }
  return packUnit16(u) | (packUnit16(v) << 16u);
}
HC_FUNCTION vec3 unpackDirection(uint word) {
  const float u = unpackUnit16(word & 0xFFFFu);
  const float v = unpackUnit16(word >> 16u);
  const float z = 1.0f - abs(u) - abs(v);
  const float t = max(-z, 0.0f);
  return normalize(vec3(u - t * signNotZero(u), v - t * signNotZero(v), z));
}

// One object as the rays see it this frame.
struct RayObject {
  mat4 toWorld;       // object → world (its pose; scales uniformly)
  vec4 rotation[3];   // the pose's rotation (columns): normals turn with it alone
  vec4 sphere;        // world bounding sphere (centre, radius): the ground's sky occluders are the others'
  float shift;        // the rays' origin shift along the normal, world units (shadowShift × scale)
  uint flags;         // ObjectInfo::flags: kObjectGround, kObjectLobePath
  uint mask;          // its instance's mask in the top level (rayMaskOf): the rays that ask what it alone blocks
  uint occluder;      // 1: one of SkyOccluders::occluders (every object but the ground)
};

// The frame's rays.
struct RayFrame {
  vec4 lightDirections[kMaxPointLights];  // toward the point lights, world, unit (xyz)
  vec4 eye;               // xyz: the camera's position (the lobe ray's mirror direction)
  vec4 sky;               // xyz: the ground's normal; w: Σ luminance·cos·ΔΩ over its hemisphere (SkyOccluders::total)
  vec4 toEnvironment[3];  // world → the light's frame (columns): where the luminance is read
  uint lights;            // point lights this frame
  uint objects;           // RayObject records
  uint width;             // the frame, pixels
  uint height;
  uint gridStep;          // render::groundSkyStep
  uint gridColumns;       // (width − 1)/step + 2
  uint gridRows;
  uint groundSky;         // 1: the ground's hidden sky is computed (fused with a ground)
  uint antialias;         // 1: edge pixels have no centre sample (the grid takes every centre)
  uint luminanceLevel;    // the map light's level (PreparedScene::restLuminance): rgb and luminance per texel
  float minShare;         // SkyOccluders::minShare
  uint objectSky;         // 1: the objects' hidden sky is computed (fused, two objects or more besides a ground)
  uint fineStep;          // groundSkyFineStep(gridStep); the fine points follow the coarse ones in `grid`
  uint fineColumns;       // (width − 1)/fineStep + 2
  uint fineRows;
  uint skyJobCapacity;   // the sky jobs the list holds (kRaysSkyJobsBinding)
};

// Object i's instance mask in the top level: a bit of its own while there
// are at most 8 objects (a ray with that cull mask sees it alone); beyond,
// objects i and i + 8 share one, and a ray asking what object i alone
// blocks steps past the others' hits (shadow_rays.rgen occludedBySelf).
HC_FUNCTION uint rayMaskOf(uint object) { return 1u << (object & 7u); }

struct RaysPush {
  uint phase;
  // 1 where `fused` takes sums from neighbours and objects hide sky from
  // each other: the samples of the smooth sum's stages 1 and on
  // (shared_smooth.h) get their HiddenLight from kRaysPhaseHidden, only
  // where they sum their own (a sum taken from the parents reads none).
  uint stagedHidden;
  uint stage;     // kRaysPhaseHidden: the smooth sum's stage
  uint ownLists;  // kRaysPhaseHidden: FusedPush::ownLists
};

#endif  // HAARCAST_CORE_SHARED_RAYS_H
