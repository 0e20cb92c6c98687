#version 450
// The shared functions of core/shared_frame.h, core/shared_tonemap.h and
// core/shared_exposure.h evaluated by the device, for the test that compares
// them with their C++ reading (tests/unit/gpu/shared_functions_test.cpp).
// Not part of any frame.
//
// Per case k (FrameCase), five results:
//   [5k]     cameraDirectionAt(basis, tanHalf, aspect, width, height, px, py), and
//            subsampleCoordinate(pixel, sub, axisBit)
//   [5k + 1] shadingFrame(n, wo)'s column x, and θₒ
//   [5k + 2] its column z, and the bits of the nearest slice
//            (sliceBlendAt(θₒ, thetaSamples, 0).first)
//   [5k + 3] the bits of tonemapCode(tone) and of meterWeight(meterLuminance(colour), object)
//   [5k + 4] eulerYXYOf(the frame): (α, β, γ)
// and, from invocation 0, meterReadout of the histograms and the push
// block's ExposurePush.
#extension GL_GOOGLE_include_directive : require
#include "haarcast/core/shared_frame.h"
#include "haarcast/core/shared_tonemap.h"
#include "common/sphere.glsl"

struct FrameCase {
  vec4 n;       // xyz: the shading normal (unit); w: the tonemapped value
  vec4 wo;      // xyz: toward the eye (unit); w: 1 for an object pixel
  vec4 point;   // px, py, width, height
  uvec4 sub;    // pixel, sub-sample k, axis bit, unused
  vec4 colour;  // rgb: meterWeight's colour
};

layout(local_size_x = kLocalSize) in;
layout(push_constant) uniform Push {
  uint count;
  uint thetaSamples;
  float tanHalf;
  float aspect;
  ExposurePush exposure;
} pc;
layout(std430, set = 0, binding = 0) readonly buffer Cases { FrameCase cases[]; };
layout(std430, set = 0, binding = 1) readonly buffer Basis { vec4 forward; vec4 right; vec4 up; };
layout(std430, set = 0, binding = 2) readonly buffer Thresholds { float threshold[kToneCodes]; };
layout(std430, set = 0, binding = 3) readonly buffer Histograms {
  uint luminanceCounts[kMeterBins];
  uint peakCounts[kMeterBins];
};
layout(std430, set = 0, binding = 4) writeonly buffer Results { vec4 results[]; };
layout(std430, set = 0, binding = 5) writeonly buffer Readout { ExposureResult readout; };

float toneThreshold(uint k) { return threshold[k]; }
uint meterLuminanceCount(uint bin) { return luminanceCounts[bin]; }
uint meterPeakCount(uint bin) { return peakCounts[bin]; }

void main() {
  const uint k = gl_GlobalInvocationID.x;
  if (k == 0u) readout = meterReadout(pc.exposure);
  if (k >= pc.count) return;
  const FrameCase c = cases[k];
  const vec3 ray = cameraDirectionAt(forward.xyz, right.xyz, up.xyz, pc.tanHalf, pc.aspect, c.point.z, c.point.w,
                                     c.point.x, c.point.y);
  results[5u * k] = vec4(ray, subsampleCoordinate(c.sub.x, c.sub.y, c.sub.z));
  float thetaOut;
  const mat3 frame = shadingFrame(c.n.xyz, c.wo.xyz, thetaOut);
  results[5u * k + 1u] = vec4(frame[0], thetaOut);
  results[5u * k + 2u] = vec4(frame[2], uintBitsToFloat(sliceBlendAt(thetaOut, pc.thetaSamples, 0u).first));
  results[5u * k + 3u] = vec4(uintBitsToFloat(tonemapCode(c.n.w)), uintBitsToFloat(meterWeight(meterLuminance(c.colour.rgb), c.wo.w != 0.0)),
                              0.0, 0.0);
  results[5u * k + 4u] = vec4(eulerYXYOf(frame), 0.0);
}
