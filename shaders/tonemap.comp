#version 450
// The "tonemap" stage's encoding: every pixel's linear radiance (resolve.comp)
// encoded as render::tonemapRgba8 does (render/tonemap.h): × 2^exposure,
// Reinhard's extended curve (white kToneWhite), sRGB transfer
// (IEC 61966-2-1), rounded, alpha 255. Local size kLocalSize, one invocation per
// pixel.
//
// The encoding is not evaluated with pow (loose on Vulkan: lavapipe's
// differs from the CPU's in 0.6% of bytes) but by counting thresholds
// (tonemapCode, core/shared_tonemap.h, which the CPU runs too): code ≥ k
// exactly when the linear value ≥ threshold[k], the transform's inverse at
// the rounding boundary (k − ½)/255, which the host computes in double
// (render::tonemapThresholds). So both give the same byte for every float. A fixed exposure is in the thresholds
// (gain 1); an automatic one, chosen on the device by exposure.comp, is the
// gain 2^stops applied to the value before the count (thresholds of 0 stops).
#extension GL_GOOGLE_include_directive : require
#include "common/frame.glsl"
#include "haarcast/core/shared_tonemap.h"

layout(local_size_x = kLocalSize) in;

layout(std430, set = 0, binding = kTonemapFrameBinding) readonly buffer Frame { FrameParams frame; };
layout(std430, set = 0, binding = kTonemapRadianceBinding) readonly buffer Radiance { vec4 radiance[]; };
layout(std430, set = 0, binding = kTonemapRgba8Binding) writeonly buffer Rgba8 { uint rgba8[]; };
layout(std430, set = 0, binding = kTonemapThresholdsBinding) readonly buffer Thresholds { float threshold[kToneCodes]; };  // [k], k = 1 … 255
layout(std430, set = 0, binding = kTonemapExposureBinding) readonly buffer Exposure { ExposureResult exposure; };

float toneThreshold(uint k) { return threshold[k]; }

void main() {
  uint p = gl_GlobalInvocationID.x;
  if (p >= frame.width * frame.height) return;
  vec3 rgb = radiance[p].rgb;
  if (exposure.gain != 1.0) rgb *= exposure.gain;
  rgba8[p] = tonemapCode(rgb.r) | (tonemapCode(rgb.g) << 8) | (tonemapCode(rgb.b) << 16) | (255u << 24);
}
