// The records the passes exchange (FrameParams, ObjectInfo, RotationSample,
// ShadeSample: core/shared_layout.h, one definition for C++ and GLSL) and
// the camera ray of a pixel.
#ifndef HAARCAST_FRAME_GLSL
#define HAARCAST_FRAME_GLSL

#include "haarcast/core/shared_layout.h"

// CameraRays::direction: pinhole through the pixel centre, row 0 at the top.
vec3 cameraDirection(FrameParams f, uint x, uint y) {
  float sx = (2.0 * (float(x) + 0.5) / float(f.width) - 1.0) * f.tanHalf * f.aspect;
  float sy = (1.0 - 2.0 * (float(y) + 0.5) / float(f.height)) * f.tanHalf;
  return normalize(f.forward.xyz + sx * f.right.xyz + sy * f.up.xyz);
}

#endif
