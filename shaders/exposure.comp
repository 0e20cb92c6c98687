#version 450
// The "tonemap" stage's exposure: render::frameLogAverage of the resolved
// frame (the log-average Rec. 709 luminance of the lit object pixels, or of
// every lit pixel when no object pixel is lit; render/tonemap.cpp
// logAverageLuminance), then render::applyExposure (the key exposure,
// clamped to ±maxStops, eased from the previous frame's), left in
// ExposureResult (shared_layout.h) for the encoding pass and the host.
// One workgroup: LOCAL invocations stride over the pixels, then a tree
// reduction in shared memory (in a fixed order, so a frame measures the same
// every time).
#extension GL_GOOGLE_include_directive : require
#include "haarcast/core/shared_layout.h"

const uint LOCAL = 128u;  // the least maxComputeWorkGroupInvocations Vulkan guarantees
layout(local_size_x = 128) in;
layout(push_constant) uniform Push { ExposurePush pc; };

layout(std430, set = 0, binding = 0) readonly buffer Frame { FrameParams frame; };
layout(std430, set = 0, binding = 1) readonly buffer Ids { uvec4 ids[]; };
layout(std430, set = 0, binding = 2) readonly buffer Radiance { vec4 radiance[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Result { ExposureResult result; };

shared float objectLog[LOCAL];
shared uint objectLit[LOCAL];
shared float allLog[LOCAL];
shared uint allLit[LOCAL];

void main() {
  uint lid = gl_LocalInvocationID.x;
  uint pixels = frame.width * frame.height;
  float oSum = 0.0, aSum = 0.0;
  uint oLit = 0u, aLit = 0u;
  for (uint p = lid; p < pixels; p += LOCAL) {
    vec3 c = radiance[p].rgb;
    float y = 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;  // Rec. 709, as logAverageLuminance
    // Black pixels carry no exposure information (and neither do NaN or ∞).
    if (!(y > 0.0) || isinf(y)) continue;
    float l = log(y);
    aSum += l;
    ++aLit;
    if (ids[p].x != 0u) {
      oSum += l;
      ++oLit;
    }
  }
  objectLog[lid] = oSum;
  objectLit[lid] = oLit;
  allLog[lid] = aSum;
  allLit[lid] = aLit;
  barrier();
  for (uint half_ = LOCAL / 2u; half_ > 0u; half_ >>= 1u) {
    if (lid < half_) {
      objectLog[lid] += objectLog[lid + half_];
      objectLit[lid] += objectLit[lid + half_];
      allLog[lid] += allLog[lid + half_];
      allLit[lid] += allLit[lid + half_];
    }
    barrier();
  }
  if (lid != 0u) return;
  uint lit = objectLit[0] != 0u ? objectLit[0] : allLit[0];
  float sumLog = objectLit[0] != 0u ? objectLog[0] : allLog[0];
  float logAverage = lit != 0u ? exp(sumLog / float(lit)) : 0.0;
  float stops;
  if (pc.automatic == 0u) {
    stops = pc.fixedStops;
  } else if (!(logAverage > 0.0)) {
    stops = pc.hasPrevious != 0u ? pc.previousStops : 0.0;  // nothing lit: keep the last exposure
  } else {
    float target = clamp(log2(pc.key / logAverage), -pc.maxStops, pc.maxStops);
    stops = pc.hasPrevious != 0u ? pc.previousStops + clamp(pc.adaptation, 0.0, 1.0) * (target - pc.previousStops)
                                 : target;
  }
  result.logAverage = logAverage;
  result.stops = stops;
  result.gain = pc.automatic != 0u ? exp2(stops) : 1.0;
  result.lit = lit;
}
