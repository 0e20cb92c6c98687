#version 450
// The "tonemap" stage's metering, first half: the frame's two exposure
// histograms by the rule of core/shared_exposure.h (every pixel with
// luminance > 0, object pixels weighted; shared_exposure.h meterWeight, the
// same rule render::meterHistograms runs on the CPU). Many workgroups: each
// strides over its share of the pixels adding integer weights to histograms
// in shared memory, then adds their non-empty bins to the frame's
// histograms (cleared before the dispatch). Integer sums: the same counts
// in any order, so exposure_readout.comp's result does not depend on how
// the pixels were split.
#extension GL_GOOGLE_include_directive : require
#include "haarcast/core/shared_layout.h"

layout(local_size_x = kExposureLocalSize) in;

layout(std430, set = 0, binding = kExposureFrameBinding) readonly buffer Frame { FrameParams frame; };
layout(std430, set = 0, binding = kExposureIdsBinding) readonly buffer Ids { uvec4 ids[]; };
layout(std430, set = 0, binding = kExposureRadianceBinding) readonly buffer Radiance { vec4 radiance[]; };
layout(std430, set = 0, binding = kExposureHistogramsBinding) buffer Histograms {
  uint luminance[kMeterBins];  // weighted counts of log2 Y, 1/16 stop bins
  uint peak[kMeterBins];       // the same of the brightest channel
} frameHistograms;

shared uint luminance[kMeterBins];
shared uint peak[kMeterBins];

void main() {
  uint lid = gl_LocalInvocationID.x;
  for (uint b = lid; b < kMeterBins; b += kExposureLocalSize) {
    luminance[b] = 0u;
    peak[b] = 0u;
  }
  barrier();
  uint pixels = frame.width * frame.height;
  uint stride = gl_NumWorkGroups.x * kExposureLocalSize;
  for (uint p = gl_GlobalInvocationID.x; p < pixels; p += stride) {
    vec3 c = radiance[p].rgb;
    float y = meterLuminance(c);
    uint w = meterWeight(y, ids[p].x != 0u);
    if (w == 0u) continue;
    atomicAdd(luminance[meterBin(y)], w);
    atomicAdd(peak[meterBin(meterPeak(c))], w);
  }
  barrier();
  for (uint b = lid; b < kMeterBins; b += kExposureLocalSize) {
    if (luminance[b] != 0u) atomicAdd(frameHistograms.luminance[b], luminance[b]);
    if (peak[b] != 0u) atomicAdd(frameHistograms.peak[b], peak[b]);
  }
}
