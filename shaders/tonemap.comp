#version 450
// The "tonemap" stage's encoding: every pixel's linear radiance (resolve.comp)
// encoded as render::tonemapRgba8 does (render/tonemap.h): × 2^exposure,
// Reinhard's extended curve (white kToneWhite), sRGB transfer
// (IEC 61966-2-1), rounded, alpha 255. Local size kLocalSize, one invocation per
// pixel.
//
// The encoding is not evaluated with pow (loose on Vulkan: lavapipe's
// differs from the CPU's in 0.6% of bytes) but by counting thresholds: code
// ≥ k exactly when the linear value ≥ threshold[k], the transform's inverse
// at the rounding boundary (k − ½)/255, which the host computes in double
// (render::tonemapThresholds) and the CPU counts the same way. So both give
// the same byte for every float. A fixed exposure is in the thresholds
// (gain 1); an automatic one, chosen on the device by exposure.comp, is the
// gain 2^stops applied to the value before the count (thresholds of 0 stops).
#extension GL_GOOGLE_include_directive : require
#include "common/frame.glsl"

layout(local_size_x = kLocalSize) in;

layout(std430, set = 0, binding = kTonemapFrameBinding) readonly buffer Frame { FrameParams frame; };
layout(std430, set = 0, binding = kTonemapRadianceBinding) readonly buffer Radiance { vec4 radiance[]; };
layout(std430, set = 0, binding = kTonemapRgba8Binding) writeonly buffer Rgba8 { uint rgba8[]; };
layout(std430, set = 0, binding = kTonemapThresholdsBinding) readonly buffer Thresholds { float threshold[256]; };  // [k], k = 1 … 255
layout(std430, set = 0, binding = kTonemapExposureBinding) readonly buffer Exposure { ExposureResult exposure; };

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
  vec3 rgb = radiance[p].rgb;
  if (exposure.gain != 1.0) rgb *= exposure.gain;
  rgba8[p] = encodeSrgb(rgb.r) | (encodeSrgb(rgb.g) << 8) | (encodeSrgb(rgb.b) << 16) | (255u << 24);
}
