#version 450
// The first pass of "tonemap": every pixel's linear radiance, left in
// `radiance` for the exposure and encoding passes and for EXR output.
//   - an uncovered interior pixel shows the backdrop: bilinear in the
//     level-backgroundLevel maps at lightRotationᵀ·direction, as
//     render::backdropRadiance, or black;
//   - an edge pixel (frame.antialias, `edges` from rotation_input.comp) is
//     the mean of its kSubsamples sub-samples: a covered one's shaded
//     radiance (slot subsampleSlot), an uncovered one the backdrop in its own
//     direction, as the CPU backend's shadePixels;
//   - a covered interior pixel keeps what the shading wrote.
// Local size kLocalSize, one invocation per pixel.
#extension GL_GOOGLE_include_directive : require
#include "common/frame.glsl"
#include "common/sphere.glsl"

layout(local_size_x = kLocalSize) in;

layout(std430, set = 0, binding = kResolveFrameBinding) readonly buffer Frame { FrameParams frame; };
layout(std430, set = 0, binding = kResolveIdsBinding) readonly buffer Ids { uvec4 ids[]; };
layout(std430, set = 0, binding = kResolveRadianceBinding) buffer Radiance { vec4 radiance[]; };  // pixels, then the sub-sample slots
layout(std430, set = 0, binding = kResolveBackgroundBinding) readonly buffer Background { float background[]; };  // [channel][row][col]
layout(std430, set = 0, binding = kResolveEdgesBinding) readonly buffer Edges { uint edges[]; };

vec3 backdrop(vec3 direction) {
  if (frame.background == 0u) return vec3(0.0);
  mat3 lightRotT = mat3(frame.lightRotT[0].xyz, frame.lightRotT[1].xyz, frame.lightRotT[2].xyz);
  vec2 tp = directionToSpherical(lightRotT * direction);
  int level = int(frame.backgroundLevel);
  int m = 1 << level;
  Taps t = bilinearTaps(level, tp.x, tp.y);
  vec3 rgb;
  for (int c = 0; c < 3; ++c) {
    uint base = uint(c * m * m);
    float top = (1.0 - t.t.y) * background[base + uint(t.rc.x * m + t.rc.z)] +
                t.t.y * background[base + uint(t.rc.x * m + t.rc.w)];
    float bottom = (1.0 - t.t.y) * background[base + uint(t.rc.y * m + t.rc.z)] +
                   t.t.y * background[base + uint(t.rc.y * m + t.rc.w)];
    rgb[c] = (1.0 - t.t.x) * top + t.t.x * bottom;
  }
  return rgb;
}

void main() {
  uint p = gl_GlobalInvocationID.x;
  uint pixels = frame.width * frame.height;
  if (p >= pixels) return;
  uint x = p % frame.width, y = p / frame.width;
  uint edge = frame.antialias != 0u ? edges[p] : 0u;
  if (edge != 0u) {
    vec3 sum = vec3(0.0);
    for (uint k = 0u; k < kSubsamples; ++k) {
      sum += (edge & (1u << k)) != 0u ? radiance[subsampleSlot(pixels, p, k)].rgb
                                      : backdrop(subsampleDirection(frame, x, y, k));
    }
    radiance[p] = vec4(sum / float(kSubsamples), 1.0);
  } else if (ids[p].x == 0u) {
    radiance[p] = vec4(backdrop(cameraDirection(frame, x, y)), 1.0);
  }
}
