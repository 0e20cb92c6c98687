// Per-frame data shared by the rotation-input and tonemap passes and the
// per-pixel shading records they exchange (vulkan_renderer.cpp fills the
// host side with the same layouts; std430).
#ifndef HAARCAST_FRAME_GLSL
#define HAARCAST_FRAME_GLSL

// The camera of render/shading.h CameraRays and the frame's settings.
struct FrameParams {
  vec4 forward;        // xyz
  vec4 right;          // xyz
  vec4 up;             // xyz
  vec4 lightRotT0;     // columns of lightRotationᵀ (xyz)
  vec4 lightRotT1;
  vec4 lightRotT2;
  float tanHalf;       // tan(fovY / 2)
  float aspect;        // width / height
  float gain;          // 2^exposureStops
  uint background;     // 1: the environment behind the objects, 0: black
  uint width;
  uint height;
  uint backgroundLevel;
  uint pad;
};

// Per object: object → world rotation (columns), where its slices, method
// data and vertices start.
struct ObjectInfo {
  vec4 rot0;
  vec4 rot1;
  vec4 rot2;
  uint sliceBase;      // global slice index of its θ slice 0
  uint methodBase;     // words into the method data
  uint thetaSamples;   // T
  uint vertexBase;     // its vertex 0 in the global vertex numbering
  uint triangleBase;   // its triangle 0 in the global triangle numbering
  uint pad0;
  uint pad1;
  uint pad2;
};

// What the triple product needs of a covered pixel besides the rotated slice.
struct ShadeSample {
  uint object;
  uint v0;             // global vertex ids of the hit triangle
  uint v1;
  uint v2;
  float b0;            // barycentrics (b0 = 1 − u − v, b1 = u, b2 = v)
  float b1;
  float b2;
  uint pixel;          // y·width + x
};

// CameraRays::direction: pinhole through the pixel centre, row 0 at the top.
vec3 cameraDirection(FrameParams f, uint x, uint y) {
  float sx = (2.0 * (float(x) + 0.5) / float(f.width) - 1.0) * f.tanHalf * f.aspect;
  float sy = (1.0 - 2.0 * (float(y) + 0.5) / float(f.height)) * f.tanHalf;
  return normalize(f.forward.xyz + sx * f.right.xyz + sy * f.up.xyz);
}

#endif
