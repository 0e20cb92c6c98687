#version 450
// The "tonemap" pass: uncovered pixels get the backdrop (bilinear in the
// level-kBackgroundLevel maps at lightRotationᵀ·direction, as
// render::backgroundRadiance) or black; every pixel is then encoded as
// render::tonemapRgba8 does (render/tonemap.h): × 2^exposure, Reinhard's
// extended curve (white kToneWhite), sRGB transfer (IEC 61966-2-1), rounded,
// alpha 255. The linear image stays in `radiance` for EXR output. Local size
// 64, one invocation per pixel.
//
// The encoding is not evaluated with pow (loose on Vulkan: lavapipe's
// differs from the CPU's in 0.6% of bytes) but by counting thresholds: code
// ≥ k exactly when the linear value ≥ threshold[k], the transform's inverse
// at the rounding boundary (k − ½)/255, which the host computes in double
// (render::tonemapThresholds) and the CPU counts the same way. So both give
// the same byte for every float.
#extension GL_GOOGLE_include_directive : require
#include "common/frame.glsl"
#include "common/sphere.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 0) readonly buffer Frame { FrameParams frame; };
layout(std430, set = 0, binding = 1) readonly buffer Ids { uvec4 ids[]; };
layout(std430, set = 0, binding = 2) buffer Radiance { vec4 radiance[]; };
layout(std430, set = 0, binding = 3) readonly buffer Background { float background[]; };  // [channel][row][col]
layout(std430, set = 0, binding = 4) writeonly buffer Rgba8 { uint rgba8[]; };
layout(std430, set = 0, binding = 5) readonly buffer Thresholds { float threshold[256]; };  // [k], k = 1 … 255

// Binary search for the largest k with value ≥ threshold[k] (0 when none,
// and for NaN, whose comparisons are false).
uint encodeSrgb(float value) {
  uint code = 0u;
  for (uint step = 128u; step > 0u; step >>= 1) {
    uint next = code + step;
    if (next <= 255u && value >= threshold[next]) code = next;
  }
  return code;
}

void main() {
  uint p = gl_GlobalInvocationID.x;
  if (p >= frame.width * frame.height) return;
  vec3 rgb;
  if (ids[p].x != 0u) {
    rgb = radiance[p].rgb;
  } else if (frame.background != 0u) {
    uint x = p % frame.width, y = p / frame.width;
    mat3 lightRotT = mat3(frame.lightRotT[0].xyz, frame.lightRotT[1].xyz, frame.lightRotT[2].xyz);
    vec2 tp = directionToSpherical(lightRotT * cameraDirection(frame, x, y));
    int level = int(frame.backgroundLevel);
    int m = 1 << level;
    Taps t = bilinearTaps(level, tp.x, tp.y);
    for (int c = 0; c < 3; ++c) {
      uint base = uint(c * m * m);
      float top = (1.0 - t.t.y) * background[base + uint(t.rc.x * m + t.rc.z)] +
                  t.t.y * background[base + uint(t.rc.x * m + t.rc.w)];
      float bottom = (1.0 - t.t.y) * background[base + uint(t.rc.y * m + t.rc.z)] +
                     t.t.y * background[base + uint(t.rc.y * m + t.rc.w)];
      rgb[c] = (1.0 - t.t.x) * top + t.t.x * bottom;
    }
    radiance[p] = vec4(rgb, 1.0);
  } else {
    rgb = vec3(0.0);
    radiance[p] = vec4(rgb, 1.0);
  }
  rgba8[p] = encodeSrgb(rgb.r) | (encodeSrgb(rgb.g) << 8) | (encodeSrgb(rgb.b) << 16) | (255u << 24);
}
