// The records the passes exchange (FrameParams, ObjectInfo, RotationSample,
// ShadeSample: core/shared_layout.h) and the camera ray of a pixel
// (core/shared_frame.h), read from the frame's FrameParams. One definition
// each for C++ and GLSL.
#ifndef HAARCAST_FRAME_GLSL
#define HAARCAST_FRAME_GLSL

#include "haarcast/core/shared_layout.h"
#include "haarcast/core/shared_frame.h"

// render::CameraRays::directionAt: through the point (px, py) of the
// frame, in pixels from its top-left corner, row 0 at the top.
vec3 cameraDirectionAt(FrameParams f, float px, float py) {
  return cameraDirectionAt(f.forward.xyz, f.right.xyz, f.up.xyz, f.tanHalf, f.aspect, float(f.width), float(f.height),
                           px, py);
}

// render::CameraRays::direction: through the pixel centre.
vec3 cameraDirection(FrameParams f, uint x, uint y) { return cameraDirectionAt(f, float(x) + 0.5, float(y) + 0.5); }

// Sub-sample k of pixel (x, y).
vec3 subsampleDirection(FrameParams f, uint x, uint y, uint k) {
  return cameraDirectionAt(f, subsampleCoordinate(x, k, 1u), subsampleCoordinate(y, k, 2u));
}

#endif
