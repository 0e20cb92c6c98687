#version 450
// The "tonemap" stage's exposure: the frame metered by the rule of
// core/shared_exposure.h (every pixel with luminance > 0, object pixels
// weighted, the key exposure held down by a highlight guard), eased from
// the previous frame's, left in ExposureResult for the encoding pass and
// the host. The per-pixel weight and the read-out are shared_exposure.h's
// meterWeight and meterReadout, which render::meterHistograms and
// render::meterExposure (render/exposure_meter.cpp) run on the CPU.
// One workgroup: kExposureLocalSize invocations stride over the pixels adding integer
// weights to two histograms in shared memory (integer sums: the same in any
// order), then one invocation reads them out in a fixed order.
#extension GL_GOOGLE_include_directive : require
#include "haarcast/core/shared_layout.h"

layout(local_size_x = kExposureLocalSize) in;
layout(push_constant) uniform Push { ExposurePush pc; };

layout(std430, set = 0, binding = kExposureFrameBinding) readonly buffer Frame { FrameParams frame; };
layout(std430, set = 0, binding = kExposureIdsBinding) readonly buffer Ids { uvec4 ids[]; };
layout(std430, set = 0, binding = kExposureRadianceBinding) readonly buffer Radiance { vec4 radiance[]; };
layout(std430, set = 0, binding = kExposureResultBinding) writeonly buffer Result { ExposureResult result; };

shared uint luminance[kMeterBins];  // weighted counts of log2 Y, 1/16 stop bins
shared uint peak[kMeterBins];       // the same of the brightest channel
uint meterLuminanceCount(uint bin) { return luminance[bin]; }
uint meterPeakCount(uint bin) { return peak[bin]; }

void main() {
  uint lid = gl_LocalInvocationID.x;
  for (uint b = lid; b < kMeterBins; b += kExposureLocalSize) {
    luminance[b] = 0u;
    peak[b] = 0u;
  }
  barrier();
  uint pixels = frame.width * frame.height;
  for (uint p = lid; p < pixels; p += kExposureLocalSize) {
    vec3 c = radiance[p].rgb;
    float y = meterLuminance(c);
    uint w = meterWeight(y, ids[p].x != 0u);
    if (w == 0u) continue;
    atomicAdd(luminance[meterBin(y)], w);
    atomicAdd(peak[meterBin(meterPeak(c))], w);
  }
  barrier();
  if (lid != 0u) return;
  result = meterReadout(pc);
}
