#version 450
// The "tonemap" stage's exposure: the frame metered by the rule of
// core/shared_exposure.h (every pixel with luminance > 0, object pixels
// weighted, the key exposure held down by a highlight guard), eased from
// the previous frame's, left in ExposureResult for the encoding pass and
// the host. render::meterHistograms and render::meterExposure
// (render/exposure_meter.cpp) are the same steps on the CPU.
// One workgroup: LOCAL invocations stride over the pixels adding integer
// weights to two histograms in shared memory (integer sums: the same in any
// order), then one invocation reads them out in a fixed order.
#extension GL_GOOGLE_include_directive : require
#include "haarcast/core/shared_layout.h"

const uint LOCAL = 128u;  // the least maxComputeWorkGroupInvocations Vulkan guarantees
layout(local_size_x = 128) in;
layout(push_constant) uniform Push { ExposurePush pc; };

layout(std430, set = 0, binding = kExposureFrameBinding) readonly buffer Frame { FrameParams frame; };
layout(std430, set = 0, binding = kExposureIdsBinding) readonly buffer Ids { uvec4 ids[]; };
layout(std430, set = 0, binding = kExposureRadianceBinding) readonly buffer Radiance { vec4 radiance[]; };
layout(std430, set = 0, binding = kExposureResultBinding) writeonly buffer Result { ExposureResult result; };

shared uint luminance[kMeterBins];  // weighted counts of log2 Y, 1/16 stop bins
shared uint peak[kMeterBins];       // the same of the brightest channel

void main() {
  uint lid = gl_LocalInvocationID.x;
  for (uint b = lid; b < kMeterBins; b += LOCAL) {
    luminance[b] = 0u;
    peak[b] = 0u;
  }
  barrier();
  uint pixels = frame.width * frame.height;
  for (uint p = lid; p < pixels; p += LOCAL) {
    vec3 c = radiance[p].rgb;
    float y = meterLuminance(c);
    // Black pixels carry no exposure information (and neither do NaN or ∞).
    if (!(y > 0.0) || isinf(y)) continue;
    uint w = ids[p].x != 0u ? kMeterObjectWeight : kMeterBackdropWeight;
    atomicAdd(luminance[meterBin(y)], w);
    atomicAdd(peak[meterBin(meterPeak(c))], w);
  }
  barrier();
  if (lid != 0u) return;
  uint total = 0u;
  precise float sumLog2 = 0.0;
  for (uint b = 0u; b < kMeterBins; ++b) {
    total += luminance[b];
    sumLog2 += float(luminance[b]) * meterBinLog2(b);
  }
  ExposureResult r;
  r.logAverage = 0.0;
  r.meanLog2 = 0.0;
  r.highlightLog2 = 0.0;
  float target = 0.0;
  if (total != 0u) {
    r.meanLog2 = sumLog2 / float(total);
    uint need = meterHighlightWeight(total);
    uint above = 0u, bin = kMeterBins - 1u;
    for (; bin > 0u; --bin) {
      above += peak[bin];
      if (above >= need) break;
    }
    r.highlightLog2 = meterBinLog2(bin);
    r.logAverage = exp2(r.meanLog2);
    target = meteredStops(r.meanLog2, r.highlightLog2, pc);
  }
  r.weight = total;
  r.stops = exposureStops(total, target, pc);
  r.gain = pc.automatic != 0u ? exp2(r.stops) : 1.0;
  r.pad0 = 0u;
  r.pad1 = 0u;
  result = r;
}
