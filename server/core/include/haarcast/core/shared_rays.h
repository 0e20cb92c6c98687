// Shadow rays on the device (shaders/shadow_rays.rgen, gpu/ray_tracing.h):
// what the ray-generation shader reads, laid out once for C++ and GLSL. Part
// of shared_layout.h, which includes it inside its namespace with its
// macros: include that instead.
//
// The rays are the host's (render/point_lights.h) for the same samples:
// each sample's point-light rays, the lobe ray, and the ground's hidden-sky
// rays, on the same coarse grid, from the same shading points. The pass
// runs in three launches of one pipeline, told apart by RaysPush::phase:
//   kRaysPhaseCentres  per covered sample: a pixel's centre sample into
//                      pixelSample[pixel] (cleared to ~0 before);
//   kRaysPhaseGrid     per grid point (RayFrame::gridColumns × gridRows):
//                      the hidden sky of an interior ground pixel, or −1;
//   kRaysPhaseMasks    per covered sample: its shadow word (fused.comp's
//                      `masks`), the ground's occlusion blended from the grid.
#ifndef HAARCAST_CORE_SHARED_RAYS_H
#define HAARCAST_CORE_SHARED_RAYS_H

HC_CONST uint kRaysPhaseCentres = 0u;
HC_CONST uint kRaysPhaseGrid = 1u;
HC_CONST uint kRaysPhaseMasks = 2u;

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

// One object as the rays see it this frame.
struct RayObject {
  mat4 toWorld;       // object → world (its pose; scales uniformly)
  vec4 rotation[3];   // the pose's rotation (columns): normals turn with it alone
  vec4 sphere;        // world bounding sphere (centre, radius): the ground's sky occluders are the others'
  float shift;        // the rays' origin shift along the normal, world units (shadowShift × scale)
  uint flags;         // ObjectInfo::flags: kObjectGround, kObjectLobePath
  uint objectPad;
  uint occluder;      // 1: one of GroundSky::occluders (every object but the ground)
};

// The frame's rays.
struct RayFrame {
  vec4 lightDirections[kMaxPointLights];  // toward the point lights, world, unit (xyz)
  vec4 eye;               // xyz: the camera's position (the lobe ray's mirror direction)
  vec4 sky;               // xyz: the ground's normal; w: Σ luminance·cos·ΔΩ over its hemisphere (GroundSky::total)
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
  uint luminanceLevel;    // the map light's luminance (PreparedScene::restLuminance): its level
  float minShare;         // GroundSky::minShare
  uint framePad;
};

struct RaysPush {
  uint phase;
};

#endif  // HAARCAST_CORE_SHARED_RAYS_H
