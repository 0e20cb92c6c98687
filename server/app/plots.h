// Exposure for the PNGs haarcast writes for viewing. (The evaluation's
// figures are drawn by tools/plot_report.py from report.json.)
#pragma once

#include "haarcast/io/image.h"

namespace haarcast::app {

// The exposure (stops) that puts the log-average luminance of the lit
// pixels at 0.18 (Reinhard's key): what haarcast's PNGs use by default.
double reinhardKeyExposure(const io::RgbImage& image);

}  // namespace haarcast::app
