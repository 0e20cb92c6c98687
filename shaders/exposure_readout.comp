#version 450
// The "tonemap" stage's metering, second half: one invocation reads the
// frame's histograms (exposure.comp) out in a fixed order into the frame's
// measure and exposure, eased from the previous frame's
// (shared_exposure.h meterReadout, which render::meterExposure runs on the
// CPU), left in ExposureResult for the encoding pass and the host.
#extension GL_GOOGLE_include_directive : require
#include "haarcast/core/shared_layout.h"

layout(local_size_x = 1) in;
layout(push_constant) uniform Push { ExposurePush pc; };

layout(std430, set = 0, binding = kExposureResultBinding) writeonly buffer Result { ExposureResult result; };
layout(std430, set = 0, binding = kExposureHistogramsBinding) readonly buffer Histograms {
  uint luminance[kMeterBins];
  uint peak[kMeterBins];
} frameHistograms;

uint meterLuminanceCount(uint bin) { return frameHistograms.luminance[bin]; }
uint meterPeakCount(uint bin) { return frameHistograms.peak[bin]; }

void main() { result = meterReadout(pc); }
