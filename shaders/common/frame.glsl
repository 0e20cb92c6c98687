// The records the passes exchange (FrameParams, ObjectInfo, RotationSample,
// ShadeSample: core/shared_layout.h, one definition for C++ and GLSL) and
// the camera ray of a pixel.
#ifndef HAARCAST_FRAME_GLSL
#define HAARCAST_FRAME_GLSL

#include "haarcast/core/shared_layout.h"

// CameraRays::directionAt: pinhole through the point (px, py) of the frame,
// in pixels from its top-left corner, row 0 at the top.
vec3 cameraDirectionAt(FrameParams f, float px, float py) {
  float sx = (2.0 * px / float(f.width) - 1.0) * f.tanHalf * f.aspect;
  float sy = (1.0 - 2.0 * py / float(f.height)) * f.tanHalf;
  return normalize(f.forward.xyz + sx * f.right.xyz + sy * f.up.xyz);
}

// CameraRays::direction: through the pixel centre.
vec3 cameraDirection(FrameParams f, uint x, uint y) { return cameraDirectionAt(f, float(x) + 0.5, float(y) + 0.5); }

// Sub-sample k of pixel (x, y) (shared_layout.h kSubsampleOffset): + in x
// when k & 1, + in y (down) when k & 2.
vec3 subsampleDirection(FrameParams f, uint x, uint y, uint k) {
  float ox = (k & 1u) != 0u ? kSubsampleOffset : -kSubsampleOffset;
  float oy = (k & 2u) != 0u ? kSubsampleOffset : -kSubsampleOffset;
  return cameraDirectionAt(f, float(x) + 0.5 + ox, float(y) + 0.5 + oy);
}

#endif
